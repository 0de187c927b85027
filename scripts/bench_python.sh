#!/usr/bin/env bash
# Benchmark: fiblet.load (.fft) vs nibabel.streamlines.load (.tck) on the
# shared medium tractogram (46 M points). Makes what is missing first: the
# build (with the Python module), build/bench-data/medium-ifod1.tck (about
# 80 s) and its .fft. Extra arguments go to bench/python_load.py (--repeat N,
# --json OUT).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${FIBLET_BUILD_DIR:-$root/build}"
data="$build/bench-data"
[ -x "$build/bin/fiblet" ] && ls "$build"/python/fiblet/_fiblet*.so >/dev/null 2>&1 || "$root/scripts/build.sh"
mkdir -p "$data"
[ -f "$data/medium-ifod1.tck" ] || "$root/../shared/data/make-tractograms.sh" -o "$data" medium
[ -f "$data/medium-ifod1.fft" ] || "$build/bin/fiblet" compress -q "$data/medium-ifod1.tck" -o "$data/medium-ifod1.fft"
PYTHONPATH="$build/python" /usr/bin/python3 "$root/bench/python_load.py" \
  "$data/medium-ifod1.tck" "$data/medium-ifod1.fft" "$@"
