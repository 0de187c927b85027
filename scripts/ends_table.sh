#!/usr/bin/env bash
# Endpoints, lengths and size of every shared tractogram, compressed with the
# defaults by two fiblet binaries (before and after a change to the encoder:
# the ENDS chunk, formats/fft-ends.md; the cubic resampling, formats/fft.md
# §5) and measured by the newer `fiblet stats --json` against its input.
# Prints a Markdown table: endpoint displacement max / mean (µm), length
# change max / mean (mm and %), Hausdorff distance (µm), the max error the
# newer file's header records (µm), tckstats mean length and `tckedit
# -minlength 100` count of the input and of each decoded file, .fft size and
# its change (%).
# Both compress with `--bits 8`: the table compares the 8-bit codec (the
# default chooses 16 bits for smooth fixed-step fibers, encode/direction_bits.hpp).
# Usage: FIBLET_BEFORE=old/bin/fiblet [FIBLET=build/bin/fiblet] scripts/ends_table.sh
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
after="${FIBLET:-$root/build/bin/fiblet}"
before="${FIBLET_BEFORE:?set FIBLET_BEFORE to a fiblet built before the change}"
data="$root/../shared/data"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
files=(small-ifod1.tck small-ifod1-step0.05.tck small-sdstream.tck small-ifod2.tck dwi-small64d-ifod1.tck
       bundles/AF_L.tck bundles/CC_ForcepsMajor.tck bundles/CST_R.tck bundles/cingulum-1.tck bundles/cingulum-2.tck
       bundles/AF_L-step0.1.tck bundles/CC_ForcepsMajor-step0.1.tck bundles/CST_R-step0.1.tck
       bundles/cingulum-1-step0.1.tck bundles/cingulum-2-step0.1.tck)
tckmean() { command -v tckstats >/dev/null && tckstats -quiet -output mean "$1" 2>/dev/null || echo nan; }
# Streamlines of at least 100 mm, as `tckedit -minlength 100` keeps them.
tcklong() {
  command -v tckedit >/dev/null || { echo nan; return; }
  tckedit -quiet -force -minlength 100 "$1" "$work/long.tck" 2>/dev/null &&
    tckinfo -count "$work/long.tck" 2>/dev/null | awk '/actual count/ {print $NF}'
}
echo "| file | step (mm) | endpoint max / mean (µm) before → after | length change max / mean (mm) before → after | mean length change (%) before → after | Hausdorff (µm) before → after | recorded max error (µm) | tckstats mean (mm): input, before, after | ≥ 100 mm (tckedit): input, before, after | .fft bytes before → after (size cost) |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for f in "${files[@]}"; do
  in="$data/$f"
  [ -f "$in" ] || continue
  for which in before after; do
    bin=$before; [ $which = after ] && bin=$after
    "$bin" compress -q --force --bits 8 "$in" -o "$work/$which.fft"
    "$after" stats --json -q "$work/$which.fft" -r "$in" > "$work/$which.json"
    "$after" decompress -q --force "$work/$which.fft" -o "$work/$which.tck"
    tckmean "$work/$which.tck" > "$work/$which.tckstats"
    tcklong "$work/$which.tck" > "$work/$which.long"
  done
  "$after" info --json "$work/after.fft" > "$work/info.json"
  /usr/bin/python3 - "$f" "$work" "$(tckmean "$in")" "$(tcklong "$in")" <<'PY'
import json, sys
name, work, tin, lin = sys.argv[1:5]
b, a = (json.load(open(f"{work}/{w}.json")) for w in ("before", "after"))
tb, ta = (open(f"{work}/{w}.tckstats").read().strip() for w in ("before", "after"))
lb, la = (open(f"{work}/{w}.long").read().strip() for w in ("before", "after"))
step = json.load(open(f"{work}/info.json"))["step_mm"]
def g(s, *k):
    v = s["geometry"]
    for key in k: v = v[key]
    return v
print(f"| {name} | {step:.3f} | "
      f"{g(b,'endpoint','max_um'):.1f} / {g(b,'endpoint','mean_um'):.1f} → {g(a,'endpoint','max_um'):.1f} / {g(a,'endpoint','mean_um'):.1f} | "
      f"{g(b,'length_change','max_um')/1e3:.3f} / {g(b,'length_change','mean_um')/1e3:.3f} → "
      f"{g(a,'length_change','max_um')/1e3:.3f} / {g(a,'length_change','mean_um')/1e3:.3f} | "
      f"{g(b,'length_change','mean_percent'):.3f} → {g(a,'length_change','mean_percent'):.3f} | "
      f"{g(b,'hausdorff_um'):.1f} → {g(a,'hausdorff_um'):.1f} | {a['header_max_error_um']:.1f} | "
      f"{float(tin):.3f}, {float(tb):.3f}, {float(ta):.3f} | {lin}, {lb}, {la} | "
      f"{b['fft_bytes']} → {a['fft_bytes']} ({100 * (a['fft_bytes'] / b['fft_bytes'] - 1):+.2f} %) |")
PY
done
