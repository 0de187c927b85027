#!/usr/bin/env bash
# Compress run time against error (bench/time_error_front.py): fiblet at
# every effort, 8 and 16 bits, --zstd, 2 threads, and the peers, in one
# interleaved run on one pinned core; writes bench/front.png (the README's
# picture), bench/results-front.md, and its section of bench/results.md.
# Makes the medium tractogram if missing (shared/data/make-tractograms.sh).
#   scripts/bench_front.sh [TCK] [time_error_front.py options: --rounds N --max-effort E --baseline OLD_FIBLET]
# Peers (built out of tree, never part of fiblet; skipped with a note when unset):
#   FIBLET_OFFICIAL_ENCODER  the official Fiblets encoder (ENC IN.tck OUT.fft): github.com/j-schertzer/Fiblets
#                            at 33cf90d, a main() calling its qfib/saveload.hpp loadTckAndSaveFft(IN, OUT, 60),
#                            built with `g++ -O3 -std=c++17 -Iqfib -Ilib/glm` (its own headers, nothing else)
#   FIBLET_QFIB              QFib's qfib program: github.com/syrousseau/qfib, its CMake Release build
# Environment: scripts/bench_env.sh.
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
if [ $# -gt 0 ] && [ "${1#--}" = "$1" ]; then tck="$1"; shift; else tck="$(medium_tractogram)"; fi
cmake --build "$build" --target fiblet_cli fiblet_exact_error >/dev/null
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
/usr/bin/python3 "$root/bench/time_error_front.py" --tck "$tck" --fiblet "$build/bin/fiblet" \
  --exact-error "$build/tests/fiblet_exact_error" --out "$work" --command "scripts/bench_front.sh $*" "$@"
cp "$work/front.png" "$out/front.png"
{
  echo "## Compress time against error (scripts/bench_front.sh)"
  echo
  echo "Commit $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?'); picture: [front.png](front.png); what each column measures: bench/time_error_front.py."
  echo
  cat "$work/front.md"
} >"$out/results-front.md"
cp "$work/front.json" "$out/results-front.json"
if [ -f "$out/results.md" ]; then
  /usr/bin/python3 "$root/bench/results_sections.py" "$out/results.md" "$out/results-front.md"
fi
