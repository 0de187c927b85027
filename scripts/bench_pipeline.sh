#!/usr/bin/env bash
# The parallel-pipeline table (issue 14, docs/parallel.md): every row from
# one run, with the machine's load (bench/pipeline_table.py), written to
# bench/results-pipeline.md and as its section of bench/results.md.
# Makes the medium tractogram if missing (shared/data/make-tractograms.sh,
# about 80 s on a quiet machine).
#   scripts/bench_pipeline.sh [TCK] [pipeline_table.py options: --repeat N --json OUT --skip-select]
# Environment: scripts/bench_env.sh.
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
if [ $# -gt 0 ] && [ "${1#--}" = "$1" ]; then tck="$1"; shift; else tck="$(medium_tractogram)"; fi
cmake --build "$build" --target fiblet_cli fiblet_bench_table fiblet_bench >/dev/null
cmake --build "$build" --target fiblet_python >/dev/null 2>&1 || echo "bench_pipeline: no Python module target" >&2
table="$(mktemp)"
trap 'rm -f "$table"' EXIT
/usr/bin/python3 "$root/bench/pipeline_table.py" --build "$build" --tck "$tck" "$@" | tee "$table"
{
  echo "## Parallel pipeline (scripts/bench_pipeline.sh)"
  echo
  echo "Command: \`scripts/bench_pipeline.sh $*\` ($(date -u +%Y-%m-%d\ %H:%M) UTC, commit $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?')); what each row measures: bench/pipeline_table.py, docs/parallel.md."
  echo
  cat "$table"
} >"$out/results-pipeline.md"
if [ -f "$out/results.md" ]; then
  /usr/bin/python3 "$root/bench/results_sections.py" "$out/results.md" "$out/results-pipeline.md"
fi
