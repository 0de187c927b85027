#!/usr/bin/env bash
# Selective-decoding benchmark (docs/select.md): makes the medium tractogram
# if missing (shared/data/make-tractograms.sh, about 80 s), builds, runs
# bench/select_bench.cpp and prints its table.
#   scripts/bench_select.sh [extra Google Benchmark flags]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${FIBLET_BUILD_DIR:-$root/build}"
data="${FIBLET_BENCH_DATA:-$build/bench-data}"
if [ ! -f "$data/medium-ifod1.tck" ]; then
  "$root/../shared/data/make-tractograms.sh" -o "$data" medium ||
    echo "bench_select: could not make the medium tractogram: benchmarking small-ifod1.tck" >&2
fi
"$root/scripts/build.sh" >/dev/null
out="$(mktemp)"
trap 'rm -f "$out"' EXIT
FIBLET_BENCH_DATA="$data" "$build/bench/fiblet_bench" --benchmark_filter='^BM_Select' \
  --benchmark_repetitions="${REPS:-5}" --benchmark_report_aggregates_only=true \
  --benchmark_out="$out" --benchmark_out_format=json "$@" >&2
/usr/bin/python3 - "$out" <<'PY'
import json, sys
runs = [b for b in json.load(open(sys.argv[1]))["benchmarks"] if b.get("aggregate_name") == "median"]
by = {b["run_name"]: b for b in runs}
# The reference is the fastest way to decode everything: decode_file with
# its default or small chunks, or a selection with an empty query.
fulls = [b for b in runs if b["run_name"].startswith(("BM_SelectFullDecode/", "BM_SelectEverything/"))]
full = min(fulls, key=lambda b: b["cpu_time"])
label = next(b.get("label", "") for b in fulls if b["run_name"].startswith("BM_SelectFullDecode/"))
print(f"file, decoder: {label}; one thread; median of repetitions; CPU time (real time in brackets); "
      f"ratios against the fastest full decode ({full['run_name']})\n")
print("| query | blocks kept | candidates (tested) | read | decoded | time | vs full decode |")
print("|---|---|---|---|---|---|---|")
for b in fulls:
    name = b["run_name"].replace("BM_SelectFullDecode/", "full decode, decode_file, chunks of ").replace(
        "BM_SelectEverything/", "full decode, select() with an empty query, chunks of ").replace(
        "decode_file, chunks of 0", "decode_file, default chunks (4096 blocks)").replace(
        "query, chunks of 0", "query, default chunks (2^15 points)")
    print(f"| {name} | 100 % | | 100 % | 100 % | {b['cpu_time']:.1f} ms ({b['real_time']:.1f}) | "
          f"{100 * b['cpu_time'] / full['cpu_time']:.1f} % |")
for b in runs:
    name = b["run_name"]
    if not name.startswith("BM_SelectQuery"):
        continue
    q = name.replace("BM_SelectQueryPread/", "(pread) ").replace("BM_SelectQuery/", "")
    print(f"| {q} | {b['kept_pct']:.2f} % | {b['tested_pct']:.2f} % | {b['read_pct']:.2f} % | {b['decoded_pct']:.2f} % | "
          f"{b['cpu_time']:.2f} ms ({b['real_time']:.2f}) | {100 * b['cpu_time'] / full['cpu_time']:.1f} % |")
load, comp = by["BM_SelectIndexLoad"], by.get("BM_SelectIndexCompute")
print(f"\nindex: {load['index_bytes'] / 1e6:.3f} MB = {load['index_pct_of_file']:.2f} % of the file without it, "
      f"{load['bytes_per_block']:.3f} bytes per block; load {load['cpu_time']:.1f} ms"
      + (f", compute by decoding {comp['cpu_time']:.1f} ms" if comp else ""))
PY
