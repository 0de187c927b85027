#!/usr/bin/env bash
# Per tractogram: compress with the default settings (one thread; the
# direction bits as the default chooses them, 16 on smooth fixed-step
# fibers: `fiblet info` tells; FIBLET_COMPRESS_ARGS="--bits 8" for the
# 8-bit codec everywhere), then the
# header's max error, the float64 reference decode's and fiblet's decoder's
# errors against the encoder's targets (tests/exact_error.hpp), size and the
# user CPU time of the whole compress run.
# Usage: scripts/exact_table.sh [FIBLET_BINARY] [FILES...] (default: every shared .tck)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${FIBLET_BUILD_DIR:-$root/build}"
fiblet="${1:-$build/bin/fiblet}"; shift || true
files=("$@")
data="$root/../shared/data"
[ ${#files[@]} -gt 0 ] || files=("$data"/*.tck "$data"/bundles/*.tck)
out="$build/exact_table"; mkdir -p "$out"
for f in "${files[@]}"; do
  fft="$out/$(basename "$f" .tck).fft"
  # shellcheck disable=SC2086
  cpu=$( { /usr/bin/time -f %U "$fiblet" compress -f -q -j 1 ${FIBLET_COMPRESS_ARGS:-} "$f" -o "$fft"; } 2>&1 )
  printf '%s: %s bytes, %s s CPU; ' "${f#"$data"/}" "$(stat -c %s "$fft")" "$cpu"
  "$build/tests/fiblet_exact_error" "$fft" "$f"
done
