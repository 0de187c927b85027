#!/usr/bin/env bash
# The parallel-pipeline table (issue 14): every row from one run, with the
# machine's load (bench/pipeline_table.py). Makes the medium tractogram if
# missing (shared/data/make-tractograms.sh, about 80 s on a quiet machine).
#   scripts/bench_pipeline.sh [TCK] [extra pipeline_table.py options: --repeat N --json OUT --skip-select]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${FIBLET_BUILD_DIR:-$root/build}"
data="${FIBLET_BENCH_DATA:-$build/bench-data}"
tck="$data/medium-ifod1.tck"
if [ $# -gt 0 ] && [ "${1#--}" = "$1" ]; then tck="$1"; shift; fi
if [ ! -f "$tck" ]; then
  mkdir -p "$data"
  "$root/../shared/data/make-tractograms.sh" -o "$data" medium
fi
cmake --build "$build" --target fiblet_cli fiblet_bench_table fiblet_bench >/dev/null
cmake --build "$build" --target fiblet_python >/dev/null 2>&1 || echo "bench_pipeline: no Python module target" >&2
uptime
/usr/bin/python3 "$root/bench/pipeline_table.py" --build "$build" --tck "$tck" "$@"
uptime
