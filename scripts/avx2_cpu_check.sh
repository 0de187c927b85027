#!/usr/bin/env bash
# What a CPU without AVX-512 runs, on any machine: valgrind's CPU (its CPUID
# offers AVX2 at most, never AVX-512) runs the CLI and the SIMD-level tests,
# so the dispatch an AVX2-only user's CPU takes is tested here too.
#   scripts/avx2_cpu_check.sh [BUILD_DIR]     (CTest: simd.avx2_only_cpu)
# Checks: compress and decompress (8 and 16 bits) give the native run's
# bytes, compress reports a level below AVX-512 (AVX2 where the host has
# it), docs/cli.md is what that CPU's binary prints, and the decoder,
# code-search, metrics, 16-bit expand and conformance tests pass at every
# level that CPU has.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-${FIBLET_BUILD_DIR:-$root/build}}"
fiblet="$build/bin/fiblet"
tests="$build/tests/fiblet_tests"
input="$root/../shared/data/small-ifod2.tck"
command -v valgrind >/dev/null || { echo "avx2_cpu_check: valgrind not found (scripts/setup.sh installs it)" >&2; exit 1; }
[ -r "$input" ] || { echo "avx2_cpu_check: $input not found" >&2; exit 1; }
vg=(valgrind --tool=none -q)
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
want=avx2 levels="scalar sse4 avx2"
grep -qw avx2 /proc/cpuinfo || want=sse4 levels="scalar sse4"

echo "== compress and decompress: the native run's bytes"
"$fiblet" compress -q -j 1 "$input" -o "$work/native.fft"
"${vg[@]}" "$fiblet" compress -j 1 --json "$input" -o "$work/cpu.fft" >"$work/report.json"
level="$(/usr/bin/python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["simd"])' "$work/report.json")"
echo "compress on valgrind's CPU: simd $level"
[ "$level" = "$want" ] || { echo "avx2_cpu_check: expected simd $want, got $level" >&2; exit 1; }
cmp "$work/native.fft" "$work/cpu.fft"
"$fiblet" decompress -q "$work/native.fft" -o "$work/native.tck"
"${vg[@]}" "$fiblet" decompress -q "$work/native.fft" -o "$work/cpu.tck"
cmp "$work/native.tck" "$work/cpu.tck"
# 16-bit files (version 17): their packed codes are expanded by a loop of their own.
"$fiblet" compress -q -j 1 --bits 16 "$input" -o "$work/native16.fft"
"$fiblet" decompress -q "$work/native16.fft" -o "$work/native16.tck"
"${vg[@]}" "$fiblet" decompress -q "$work/native16.fft" -o "$work/cpu16.tck"
cmp "$work/native16.tck" "$work/cpu16.tck"

echo "== docs/cli.md from that CPU's binary"
"${vg[@]}" "$fiblet" help --markdown >"$work/cli.md"
diff -u "$root/docs/cli.md" "$work/cli.md"

echo "== SIMD-level tests"
# (BlockLanes.SharedTractogramBlocks* repeats the others on ten times the data.)
filter='DecodeSimd.RandomBlocks*:DecodeSimd.NamesParseAndResolve:DecodeSimd.InvalidPointCounts*:BlockLanes.*'
filter+=':Conformance.*:GeometryError.VectorsEqualScalarLoops:ErrorStats.*:Fft16.PackedCodes*-BlockLanes.SharedTractogramBlocks*'
"${vg[@]}" "$tests" --gtest_filter="$filter" --gtest_brief=1 | tee "$work/tests.log"
grep -qx "\[ levels   \] $levels" "$work/tests.log" || {
  echo "avx2_cpu_check: the tests did not run the levels $levels" >&2
  exit 1
}
echo "avx2_cpu_check: ok (levels $levels)"
