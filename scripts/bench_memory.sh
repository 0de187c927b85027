#!/usr/bin/env bash
# Bounded-memory benchmark: generates a large synthetic .tck on the fly
# (bench/make_big_tck.cpp; never stored in the repository), then compresses,
# verifies, decompresses and compares it (fiblet stats), printing each step's
# peak RSS (/usr/bin/time -v) and throughput. Goal: peak RSS <= 256 MB for any
# input size. The files are deleted at the end.
#   scripts/bench_memory.sh [GB] [POINTS_PER_FIBER] [WORKDIR]
#   defaults: 5 GB, 80 points per fiber (about 5 M fibers), build/bench-memory
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
gb="${1:-5}"
points="${2:-80}"
work="${3:-$root/build/bench-memory}"
build="${FIBLET_BUILD_DIR:-$root/build}"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DFIBLET_BUILD_BENCH=ON >/dev/null
cmake --build "$build" --target fiblet_cli make_big_tck -j"${FIBLET_BUILD_JOBS:-2}" >/dev/null
fiblet="$build/bin/fiblet"
mkdir -p "$work"
tck="$work/big.tck" fft="$work/big.fft" back="$work/big-decoded.tck"
trap 'rm -f "$tck" "$fft" "$back"' EXIT

# run LABEL INPUT_BYTES POINTS -- command...: one line of the table.
run() {
  local label="$1" bytes="$2" npoints="$3"
  shift 4
  local log="$work/$label.time"
  /usr/bin/time -v "$@" >"$work/$label.out" 2>"$log"
  local rss_kb secs
  rss_kb=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$log")
  secs=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$log" |
    awk -F: '{ s = 0; for (i = 1; i <= NF; i++) s = s * 60 + $i; print s }')
  awk -v l="$label" -v r="$rss_kb" -v s="$secs" -v b="$bytes" -v p="$npoints" 'BEGIN {
    printf "%-12s %9.1f s %10.1f MB peak RSS %10.0f MB/s %9.1f M points/s\n", l, s, r / 1024, b / 1e6 / s, p / 1e6 / s }'
}

echo "== generating $gb GB, ~$points points per fiber, into $work"
"$build/bench/make_big_tck" "$tck" --bytes "${gb}e9" --points "$points" 2>&1 | tee "$work/generate.out"
tck_bytes=$(stat -c %s "$tck")
fibers=$(sed -n 's/.*: \([0-9]*\) fibers, \([0-9]*\) points.*/\1/p' "$work/generate.out")
npoints=$(sed -n 's/.*: \([0-9]*\) fibers, \([0-9]*\) points.*/\2/p' "$work/generate.out")
echo "input: $tck_bytes bytes, $fibers fibers, $npoints points"
echo
printf '%-12s %11s %22s %24s\n' step wall "" "throughput (.tck bytes, points)"
# --bits 8: the default would give these smooth random walks 16 bits (3.6 um
# of length for 1.9 um of point error at 8 bits); the recorded figures are 8-bit.
run compress "$tck_bytes" "$npoints" -- "$fiblet" compress -q --bits 8 "$tck" -o "$fft" -f
run verify "$tck_bytes" "$npoints" -- "$fiblet" verify -q "$fft"
run decompress "$tck_bytes" "$npoints" -- "$fiblet" decompress -q "$fft" -o "$back" -f
run stats "$tck_bytes" "$npoints" -- "$fiblet" stats "$fft" -r "$tck" -q
echo
echo ".fft: $(stat -c %s "$fft") bytes ($(awk -v a="$tck_bytes" -v b="$(stat -c %s "$fft")" 'BEGIN { printf "%.2f", a / b }')x smaller)"
sed -n '/^error/,$p' "$work/stats.out"
# The decoded .tck holds the same number of fibers as the input.
"$fiblet" info "$back" --json | grep -q "\"count\", \"0*$fibers\"" && echo "decoded .tck: $fibers fibers, as the input"
