#!/usr/bin/env bash
# The viewer's benchmark in one command: `fiblet render --bench` for every
# technique (lines, tubes, capsules; each transparency mode; the voxel ray
# tracer opaque, with AO + shadows, transparent; ODF glyphs), overview and
# close-up, into one JSON and one Markdown table naming the GPU and driver.
#
#   scripts/bench_viewer.sh [--quick] [--input FILE] [--odf IMAGE] [--out DIR]
#                           [--size WxH] [--frames N] [--fiblet BIN]
#   scripts/bench_viewer.sh --bundle DIR   # carry the build to a GPU machine
#
# Full (default): the medium tractogram (scripts/bench_env.sh makes it),
# 1920x1080, 5 frames, glyphs of the phantom FOD (build/tests/phantom-fod/,
# made by the test suite), results in bench/results-viewer.{json,md}.
# --quick: a bundle of the shared data at 240x135, 1 frame, results in
# build/bench-viewer-quick/ (the test suite runs it on llvmpipe, so the
# script cannot rot). On a software renderer the figures say only that the
# path runs; absolute times mean something on a GPU.
#
# --bundle DIR copies the fiblet binary, the shared libraries it loads
# (but the C runtime and the GL/EGL driver libraries, which must be the GPU
# machine's own), this script and its table maker into DIR: on a machine
# with a GPU driver but no packages, run DIR/run.sh [--input FILE.fft ...].
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
fiblet="${FIBLET:-$root/build/bin/fiblet}"
table="$root/bench/viewer_table.py"
quick=0 input="" odf="" out="" size="" frames="" bundle=""
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=1 ;;
    --input) input="$2"; shift ;;
    --odf) odf="$2"; shift ;;
    --out) out="$2"; shift ;;
    --size) size="$2"; shift ;;
    --frames) frames="$2"; shift ;;
    --fiblet) fiblet="$2"; shift ;;
    --bundle) bundle="$2"; shift ;;
    -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
    *) echo "bench_viewer.sh: unknown argument $1 (--help)" >&2; exit 2 ;;
  esac
  shift
done
[ -x "$fiblet" ] || { echo "bench_viewer.sh: no fiblet binary at $fiblet (scripts/build.sh, or --fiblet BIN)" >&2; exit 2; }

if [ -n "$bundle" ]; then
  mkdir -p "$bundle/lib"
  cp "$fiblet" "$bundle/fiblet"
  cp "$0" "$bundle/bench_viewer.sh"
  cp "$table" "$bundle/viewer_table.py"
  # Every resolved library but the C runtime and the GL/EGL dispatch and
  # driver libraries (the GPU machine's own driver must be used).
  ldd "$fiblet" | awk '/=> \// {print $3}' |
    grep -Ev '/(libc|libm|libdl|libpthread|librt|ld-linux[^/]*|libGL[^/]*|libEGL[^/]*|libGLX[^/]*|libGLdispatch|libOpenGL|libgbm|libdrm[^/]*|libX[^/]*|libxcb[^/]*|libwayland[^/]*)\.so' |
    while read -r lib; do cp -L "$lib" "$bundle/lib/"; done
  cat > "$bundle/run.sh" <<'EOF'
#!/usr/bin/env bash
# Runs the viewer benchmark with the carried binary and libraries.
here="$(cd "$(dirname "$0")" && pwd)"
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
FIBLET_VIEWER_TABLE="$here/viewer_table.py" exec "$here/bench_viewer.sh" --fiblet "$here/fiblet" --out "${OUT:-$here/results}" "$@"
EOF
  chmod +x "$bundle/run.sh"
  echo "bundle in $bundle ($(ls "$bundle/lib" | wc -l) libraries): copy it to the GPU machine with a .fft, then $bundle/run.sh --input FILE.fft" >&2
  exit 0
fi
table="${FIBLET_VIEWER_TABLE:-$table}"

views="overview,close-up"  # the views timed (the full decodes once, with the first case)
if [ "$quick" = 1 ]; then
  : "${size:=240x135}" "${frames:=1}" "${out:=$root/build/bench-viewer-quick}"
  mkdir -p "$out"
  if [ -z "$input" ]; then
    input="$out/cst.fft"
    "$fiblet" compress -q -f "$root/../shared/data/bundles/CST_R.tck" -o "$input"
  fi
else
  : "${size:=1920x1080}" "${frames:=5}" "${out:=$root/bench}"
  if [ -z "$input" ]; then
    # shellcheck source=bench_env.sh
    source "$root/scripts/bench_env.sh"
    input="$root/build/bench-data/medium-ifod1.fft"
    [ -f "$input" ] || "$fiblet" compress -q "$(medium_tractogram)" -o "$input"
  fi
fi
[ -z "$odf" ] && [ -f "$root/build/tests/phantom-fod/phantom-fod.nii" ] && odf="$root/build/tests/phantom-fod/phantom-fod.nii"
mkdir -p "$out"

# technique | render options
cases=(
  "lines|--style lines"
  "tubes|--style tubes"
  "capsules|--style capsules"
  "lines, sorted transparency|--style lines --opacity 0.3 --transparency sorted"
  "lines, Voxlines transparency|--style lines --opacity 0.3 --transparency voxlines"
  "lines, unsorted transparency|--style lines --opacity 0.3 --transparency unsorted"
  "tubes, sorted transparency|--style tubes --opacity 0.3 --transparency sorted"
  "capsules, sorted transparency|--style capsules --opacity 0.3 --transparency sorted"
  "voxel-rt|--engine voxel-rt"
  "voxel-rt, AO + shadows|--engine voxel-rt --ao --shadows"
  "voxel-rt, transparent|--engine voxel-rt --opacity 0.3"
)
if [ -n "$odf" ]; then
  cases+=("lines + ODF glyphs|--style lines --odf $odf")
else
  echo "bench_viewer.sh: no ODF image (--odf, or build/tests/phantom-fod/ from the test suite): glyphs not measured" >&2
fi

rows="$out/results-viewer.tsv"
: > "$rows"
first=1
for c in "${cases[@]}"; do
  name="${c%%|*}" options="${c#*|}"
  # The full decodes are timed once, with the first case.
  v="$views"; [ "$first" = 1 ] && v="$views,decode"; first=0
  echo "bench_viewer.sh: $name" >&2
  # shellcheck disable=SC2086
  result="$("$fiblet" render "$input" --bench --json --bench-views "$v" --frames "$frames" --size "$size" $options)"
  printf '%s\t%s\t%s\n' "$name" "$options" "$result" >> "$rows"
done
python3 "$table" "$rows" --json "$out/results-viewer.json" --markdown "$out/results-viewer.md" \
  --command "scripts/bench_viewer.sh $([ "$quick" = 1 ] && echo --quick) --size $size --frames $frames"
rm -f "$rows"
echo "bench_viewer.sh: $out/results-viewer.md" >&2
