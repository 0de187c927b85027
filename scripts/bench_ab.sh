#!/usr/bin/env bash
# Before/after compress time of two fiblet binaries: alternated round by
# round on one pinned core (timings drift by 10-30 % between runs, so a
# change to the hot path is judged within one run), CPU seconds (user +
# sys) per run, medians, the ratio, and whether both wrote the same bytes.
#   scripts/bench_ab.sh [--tck TCK] [--rounds N] [--core C] [--effort E]... OLD_FIBLET NEW_FIBLET [-- COMPRESS_OPTIONS...]
# Defaults: the medium tractogram (made if missing), 5 rounds, core 1,
# efforts 1 and 0. Environment: scripts/bench_env.sh.
set -euo pipefail
source "$(dirname "$0")/bench_env.sh"
tck="" rounds=5 core=1 efforts=()
while [ $# -gt 0 ]; do
  case "$1" in
    --tck) tck="$2"; shift 2 ;;
    --rounds) rounds="$2"; shift 2 ;;
    --core) core="$2"; shift 2 ;;
    --effort) efforts+=("$2"); shift 2 ;;
    --) break ;;
    -*) echo "bench_ab: unknown option $1" >&2; exit 2 ;;
    *) break ;;
  esac
done
[ $# -ge 2 ] || { echo "usage: scripts/bench_ab.sh [--tck TCK] [--rounds N] [--core C] [--effort E]... OLD NEW [-- OPTIONS]" >&2; exit 2; }
old="$1" new="$2"; shift 2
[ "${1:-}" = "--" ] && shift
for bin in "$old" "$new"; do [ -x "$bin" ] || { echo "bench_ab: $bin is not an executable" >&2; exit 2; }; done
[ -n "$tck" ] || tck="$(medium_tractogram)"
[ ${#efforts[@]} -gt 0 ] || efforts=(1 0)
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
pin=(); command -v taskset >/dev/null && pin=(taskset -c "$core")
for e in "${efforts[@]}"; do
  for r in $(seq "$rounds"); do
    for side in old new; do
      bin="$old"; [ "$side" = new ] && bin="$new"
      /usr/bin/time -f "$side $e %U %S" -o "$work/time" "${pin[@]}" "$bin" compress "$tck" -o "$work/$side-$e.fft" \
        -j 1 -e "$e" -q -f "$@"
      cat "$work/time" >>"$work/runs"
    done
  done
  cmp -s "$work/old-$e.fft" "$work/new-$e.fft" && echo "same $e" >>"$work/runs" || echo "differ $e" >>"$work/runs"
done
/usr/bin/python3 - "$work/runs" "$tck" "$rounds" "$core" <<'PY'
import statistics, sys
runs, same = {}, {}
for line in open(sys.argv[1]):
    f = line.split()
    if f[0] in ("same", "differ"):
        same[f[1]] = f[0] == "same"
    else:
        runs.setdefault((f[0], f[1]), []).append(float(f[2]) + float(f[3]))
print(f"{sys.argv[2]}: compress -j 1, core {sys.argv[4]}, {sys.argv[3]} alternated rounds, CPU seconds (user + sys)")
for e in sorted(same, reverse=True):
    old, new = statistics.median(runs[("old", e)]), statistics.median(runs[("new", e)])
    print(f"effort {e}: old {old:.3f} s, new {new:.3f} s (medians), new/old {new / old:.3f}; "
          f"bytes {'the same' if same[e] else 'DIFFER'}")
    for side in ("old", "new"):
        print(f"  {side}: " + " ".join(f"{t:.2f}" for t in runs[(side, e)]))
PY
