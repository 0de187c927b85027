#!/usr/bin/env bash
# Image masks as regions on the medium tractogram (docs/select.md): `fiblet
# extract --include MASK` against a full decode and against tckedit, and
# Python's fiblet.load(roi=...) against fiblet.load(). Makes what is missing
# first (the medium .tck, about 80 s; its .fft; two masks, written by nibabel).
#   scripts/bench_masks.sh            (REPS=5 repetitions, medians)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${FIBLET_BUILD_DIR:-$root/build}"
data="${FIBLET_BENCH_DATA:-$build/bench-data}"
reps="${REPS:-5}"
fiblet="$build/bin/fiblet"
mkdir -p "$data"
[ -f "$data/medium-ifod1.tck" ] || "$root/../shared/data/make-tractograms.sh" -o "$data" medium
[ -f "$data/medium-ifod1.fft" ] || "$fiblet" compress -q "$data/medium-ifod1.tck" -o "$data/medium-ifod1.fft"
fft="$data/medium-ifod1.fft" tck="$data/medium-ifod1.tck"
# Balls of 10 and 25 mm radius around the origin on a 1 mm grid (uint8 NIfTI, gzip).
/usr/bin/python3 - "$data" <<'PY'
import sys, numpy as np, nibabel as nib
aff = np.eye(4); aff[:3, 3] = -50
xyz = np.indices((101, 101, 101)).reshape(3, -1).T - 50.0
for r in (10, 25):
    m = (np.linalg.norm(xyz, axis=1) <= r).reshape(101, 101, 101).astype(np.uint8)
    nib.Nifti1Image(m, aff).to_filename(f"{sys.argv[1]}/ball{r}.nii.gz")
PY
cat "$fft" "$tck" >/dev/null  # warm page cache

median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
seconds() {  # wall seconds of a command, median of $reps runs
  for _ in $(seq "$reps"); do
    /usr/bin/time -f %e "$@" 2>&1 >/dev/null | tail -1
  done | median
}
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
echo "| command | fibers kept | wall s (median of $reps) |"
echo "|---|---|---|"
row() {  # label, fibers, command...
  local label="$1" fibers="$2"; shift 2
  echo "| \`$label\` | $fibers | $(seconds "$@") |"
}
kept() { "$fiblet" extract "$fft" -o "$out/k.tck" -f --json "$@" | /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["fibers"])'; }
row "fiblet decompress (full decode)" 50000 "$fiblet" decompress -q -f "$fft" -o "$out/full.tck"
row "fiblet extract (no criteria)" 50000 "$fiblet" extract -q -f "$fft" -o "$out/all.tck"
row "fiblet extract --include 0,0,0,10" "$(kept --include 0,0,0,10)" "$fiblet" extract -q -f "$fft" -o "$out/s.tck" --include 0,0,0,10
for r in 10 25; do
  m="$data/ball$r.nii.gz"
  row "fiblet extract --include ball$r.nii.gz" "$(kept --include "$m")" "$fiblet" extract -q -f "$fft" -o "$out/m.tck" --include "$m"
  row "tckedit medium.tck -include ball$r.nii.gz" "-" tckedit -quiet -force -nthreads 0 "$tck" "$out/t.tck" -include "$m"
done
echo
echo "| Python (PYTHONPATH=$build/python) | fibers | wall s (median of $reps) |"
echo "|---|---|---|"
PYTHONPATH="$build/python" /usr/bin/python3 - "$fft" "$data" "$reps" <<'PY'
import statistics, sys, time
import fiblet
fft, data, reps = sys.argv[1], sys.argv[2], int(sys.argv[3])
cases = [("fiblet.load(fft)", {}), ("fiblet.load(fft, roi=(0, 0, 0, 10))", {"roi": (0, 0, 0, 10)}),
         ("fiblet.load(fft, roi='ball10.nii.gz')", {"roi": f"{data}/ball10.nii.gz"}),
         ("fiblet.load(fft, roi='ball25.nii.gz')", {"roi": f"{data}/ball25.nii.gz"}),
         ("fiblet.load(fft, threads=1)", {"threads": 1}),
         ("fiblet.load(fft, roi=(0, 0, 0, 10), threads=1)", {"roi": (0, 0, 0, 10), "threads": 1})]
for label, kw in cases:
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        s = fiblet.load(fft, **kw)
        times.append(time.perf_counter() - t0)
        n = len(s)
        del s
    print(f"| `{label}` | {n} | {statistics.median(times):.3f} |")
PY
