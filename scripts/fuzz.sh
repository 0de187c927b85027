#!/usr/bin/env bash
# Builds the libFuzzer harnesses (clang, ASan+UBSan; fuzz/) into build-fuzz/
# and runs each one in turn, one process at a time.
#   scripts/fuzz.sh [SECONDS] [TARGET...]     SECONDS per target (default 60)
#   FIBLET_FUZZ_RUNS=N scripts/fuzz.sh S      stop at N executions or S seconds
#   FIBLET_FUZZ_TIMEOUT=S                     seconds one input may take (default 120:
#                                             valid inputs that resample to millions of
#                                             points take tens of seconds under ASan)
# Seeds are written by fiblet_fuzz_seeds (shared test files + hand-made edge
# files); the corpus each run grows is kept in build-fuzz/corpus/TARGET.
# A crash leaves its input in build-fuzz/crashes/TARGET/ and fails the script:
# fix the bug, then add the input to fuzz/regressions/TARGET/ (replayed by
# tests/fuzz_regression_test.cpp in every test run).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-60}"
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(tck_reader_fuzz compress_fuzz fft_file_fuzz fft_trailer_fuzz decode_blocks_fuzz
  streamline_source_fuzz image_fuzz)
cxx="${FIBLET_FUZZ_CXX:-$(command -v clang++-14 || command -v clang++ || true)}"
if [ -z "$cxx" ]; then
  echo "fuzz.sh: clang++ not found (scripts/setup.sh installs clang-14 and libclang-rt-14-dev)" >&2
  exit 2
fi
build="${FIBLET_FUZZ_BUILD_DIR:-$root/build-fuzz}"
jobs="${FIBLET_FUZZ_BUILD_JOBS:-2}"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DFIBLET_FUZZ=ON -DFIBLET_BUILD_TESTS=OFF -DFIBLET_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" --target fuzzers -j"$jobs"
rm -rf "$build/seeds"
ASAN_OPTIONS=detect_leaks=0 "$build/fuzz/fiblet_fuzz_seeds" "$root/../shared/data" "$build/seeds"

# A small quarantine and no malloc fill: 3x more executions per second, and
# use-after-free of recent frees is still caught.
export ASAN_OPTIONS="${ASAN_OPTIONS:-quarantine_size_mb=16:malloc_context_size=8:max_malloc_fill_size=0}"
limit=(-max_total_time="$seconds")
[ -z "${FIBLET_FUZZ_RUNS:-}" ] || limit+=(-runs="$FIBLET_FUZZ_RUNS")
status=0
summary=""
for t in "${targets[@]}"; do
  corpus="$build/corpus/$t" crashes="$build/crashes/$t"
  mkdir -p "$corpus" "$crashes"
  log="$build/fuzz-$t.log"
  extra=()
  [ ! -d "$root/fuzz/regressions/$t" ] || extra=("$root/fuzz/regressions/$t")
  echo "== $t (${limit[*]})"
  start=$(date +%s)
  if "$build/fuzz/$t" "${limit[@]}" -max_len="${FIBLET_FUZZ_MAX_LEN:-16384}" -timeout="${FIBLET_FUZZ_TIMEOUT:-120}" -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="$crashes/" "$corpus" "$build/seeds/$t" "${extra[@]}" >"$log" 2>&1; then
    result=ok
  else
    result="FAILED (see $log; input in $crashes/)"
    status=1
    tail -40 "$log" >&2
  fi
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 || true)
  line="$t: ${execs:-?} executions in $(( $(date +%s) - start )) s (${rate:-?}/s), ${cov:-cov: ?}, corpus $(ls "$corpus" | wc -l), $result"
  echo "$line"
  summary+="$line"$'\n'
done
echo "== summary"
printf '%s' "$summary"
exit $status
