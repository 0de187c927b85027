#!/usr/bin/env bash
# The main job: installs dependencies, builds, then compresses a real
# tractogram (../shared/data/small-ifod1.tck when present, else one generated
# here), decodes it back to .tck, and prints sizes and error statistics.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
"$root/scripts/build.sh" > "${FIBLET_BUILD_DIR:-$root/build}.log" 2>&1 || { cat "${FIBLET_BUILD_DIR:-$root/build}.log"; exit 1; }
fiblet="${FIBLET_BUILD_DIR:-$root/build}/bin/fiblet"
work="${FIBLET_DEMO_DIR:-$root/build/demo}"
mkdir -p "$work"

input="$(realpath -m "$root/../shared/data/small-ifod1.tck")"
if [ ! -f "$input" ]; then
  input="$work/generated.tck"
  echo "== ../shared/data not found: generating $input"
  /usr/bin/python3 "$root/scripts/make_synthetic_tck.py" --fibers 2000 --step 0.1 --seed 1 "$input"
fi

echo "== fiblet info $input"
"$fiblet" info "$input" | head -8
echo
echo "== fiblet compress"
"$fiblet" compress "$input" -o "$work/demo.fft" --force
echo
echo "== fiblet decompress"
"$fiblet" decompress "$work/demo.fft" -o "$work/demo-decoded.tck" --force
echo
echo "== fiblet stats (decoded vs original, measured point by point)"
"$fiblet" stats "$work/demo.fft" --reference "$input"
echo
ls -l "$input" "$work/demo.fft" "$work/demo-decoded.tck"
