#!/usr/bin/env bash
# The rate-distortion-speed table: every decoder and codec option of fiblet
# against the baselines, on one tractogram, written to bench/results.md and
# bench/results.png (docs/decode.md explains the columns).
#
#   scripts/bench_table.sh [TCK]
#
# TCK defaults to the shared medium tractogram, generated into
# $BUILD/bench-data when missing (make-tractograms.sh; a synthetic one from
# scripts/make_synthetic_tck.py if that fails). Environment: BUILD (build
# directory, default build/), REPEAT (best of N timings, default 7),
# OUT (output directory, default bench/).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${BUILD:-$root/build}"
out="${OUT:-$root/bench}"
repeat="${REPEAT:-7}"
data="$build/bench-data"
work="$build/bench-table"
mkdir -p "$data" "$work" "$out"

FIBLET_BUILD_DIR="$build" "$root/scripts/build.sh" >/dev/null
cli="$build/bin/fiblet"
table="$build/bench/fiblet_bench_table"

tck="${1:-$data/medium-ifod1.tck}"
if [ ! -f "$tck" ]; then
  if [ "$tck" = "$data/medium-ifod1.tck" ] && "$root/../shared/data/make-tractograms.sh" -o "$data" medium >&2; then
    :
  else
    echo "bench_table: making a synthetic tractogram instead" >&2
    tck="$data/synthetic.tck"
    /usr/bin/python3 "$root/scripts/make_synthetic_tck.py" "$tck" --fibers 50000 --min-points 200 --max-points 1640
  fi
fi
rows="$work/rows.jsonl"
: >"$rows"
log() { echo "bench_table: $*" >&2; }
# Appends one JSON row, with extra fields (already JSON) merged in.
add_row() { /usr/bin/python3 -c 'import json,sys; r=json.loads(sys.argv[1]); r.update(json.loads(sys.argv[2])); print(json.dumps(r))' "$1" "$2" >>"$rows"; }
# Peak RSS (KiB) of a command, its stdout kept in $work/stdout.
rss_of() { /usr/bin/time -f %M -o "$work/rss" "$@" >"$work/stdout"; cat "$work/rss"; }

# fiblet: compress with 1 and 2 threads (same file), then every decoder.
compress_rows() {  # label options...
  local label="$1"; shift
  local fft="$work/$label.fft" json rss1 rss2 enc1 enc2
  log "compress ($label)"
  rss1=$(rss_of "$cli" compress "$tck" -o "$fft" -f --json -j 1 "$@")
  enc1=$(cat "$work/stdout")
  rss2=$(rss_of "$cli" compress "$tck" -o "$fft" -f --json -j 2 "$@")
  enc2=$(cat "$work/stdout")
  local decoders
  if [ "$label" = "fiblet-8bit" ]; then
    mapfile -t decoders < <("$cli" decompress --help | sed -n 's/.*SIMD level: //p' | tr ',' '\n' | tr -d ' ')
  else
    decoders=(auto)
  fi
  for d in "${decoders[@]}"; do
    for t in 1 2; do
      log "decode ($label, $d, $t threads)"
      if json=$("$table" decode "$fft" --decoder "$d" --threads "$t" --repeat "$repeat"); then
        local enc; enc=$([ "$t" = 1 ] && echo "$enc1" || echo "$enc2")
        add_row "$json" "$(/usr/bin/python3 -c 'import json,sys; e=json.loads(sys.argv[1]); print(json.dumps({"label": sys.argv[2], "encode_seconds": e["seconds"], "max_error_um": e["max_error_um"], "mean_error_um": e["mean_error_um"], "bytes": e["output_bytes"], "encode_rss_kib": int(sys.argv[3])}))' "$enc" "$label" "$([ "$t" = 1 ] && echo "$rss1" || echo "$rss2")")"
      else
        log "decode of $label failed: row skipped"
      fi
    done
  done
}
# --bits 8: the default chooses the bits per file (16 for smooth fixed-step fibers).
compress_rows fiblet-8bit --bits 8

# Every other option the codec has; a row whose option this build lacks is
# skipped (it appears once the option exists).
help="$("$cli" compress --help)"
while IFS='|' read -r label probe options; do
  [ -z "$label" ] && continue
  if grep -q -- "$probe" <<<"$help"; then
    # shellcheck disable=SC2086
    compress_rows "$label" $options
  else
    log "no '$probe' option in this build: '$label' row skipped"
  fi
done <<'ROWS'
fiblet-16bit|--bits|--bits 16
fiblet-zstd|--zstd|--zstd
ROWS

log "baselines"
add_row "$("$table" tck-parse "$tck" --repeat "$repeat")" '{"label": "tck"}'
# Read from the disk (each file dropped from the page cache before each run).
log "cold reads"
add_row "$("$table" tck-parse "$tck" --repeat 3 --cold 1)" '{"label": "tck-cold"}'
fft="$work/fiblet-8bit.fft"
"$cli" compress "$tck" -o "$fft" -f -q --bits 8
add_row "$("$table" decode "$fft" --threads 1 --repeat 3 --cold 1)" \
  "$(/usr/bin/python3 -c 'import json,sys; print(json.dumps({"label": "fiblet-8bit-cold", "bytes": __import__("os").path.getsize(sys.argv[1])}))' "$fft")"

for level in 3 19; do
  log "zstd -$level"
  add_row "$("$table" zstd "$tck" --level "$level" --repeat "$repeat")" "{\"label\": \"tck+zstd-$level\"}"
done
add_row "$("$table" float16 "$tck" --repeat "$repeat")" '{"label": "float16"}'
log "sequential decoder without blocks"
add_row "$("$table" sequential "$tck" --repeat "$repeat")" '{"label": "sequential"}'

log "micro-benchmarks"
"$build/bench/fiblet_bench" --benchmark_min_time=0.5 --benchmark_format=json >"$work/micro.json" 2>/dev/null

/usr/bin/python3 "$root/bench/make_results.py" --rows "$rows" --micro "$work/micro.json" --tck "$tck" \
  --command "scripts/bench_table.sh${1:+ $1}" --md "$out/results.md" --png "$out/results.png"
cp "$rows" "$out/results-rows.jsonl"
cp "$work/micro.json" "$out/results-micro.json"
log "wrote $out/results.md and $out/results.png"
