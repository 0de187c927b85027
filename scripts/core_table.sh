#!/usr/bin/env bash
# Compresses every shared tractogram and prints a Markdown table: sizes,
# ratio, max/mean error (µm, measured by `fiblet stats` against the input),
# the symmetric metrics (Hausdorff, endpoint displacement, length change),
# compress and decompress wall time. The direction bits are the default's
# (8); `scripts/core_table.sh --bits auto` lets the data choose per file (16
# where 8-bit codes would change the fibers' lengths beyond their point
# error; "16-bit" after the ratio).
# Usage: scripts/core_table.sh [fiblet args...]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
fiblet="${FIBLET:-$root/build/bin/fiblet}"
data="$root/../shared/data"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
files=(small-ifod1.tck small-ifod1-step0.05.tck small-sdstream.tck small-ifod2.tck dwi-small64d-ifod1.tck
       bundles/AF_L-step0.1.tck bundles/CC_ForcepsMajor-step0.1.tck bundles/CST_R-step0.1.tck
       bundles/cingulum-1-step0.1.tck bundles/cingulum-2-step0.1.tck)
echo "| file | .tck | .fft | ratio | max / mean error (µm) | Hausdorff (µm) | endpoints max / mean (µm) | length change max / mean (µm, mean %) | compress (s) | decompress (s) |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for f in "${files[@]}"; do
  in="$data/$f"
  [ -f "$in" ] || continue
  out="$work/$(basename "$f" .tck).fft"
  t0=$(date +%s.%N)
  "$fiblet" compress -q "$in" -o "$out" "$@"
  t1=$(date +%s.%N)
  "$fiblet" decompress -q "$out" -o "$work/back.tck" --force
  t2=$(date +%s.%N)
  "$fiblet" stats "$out" -r "$in" --json -q > "$work/stats.json"
  "$fiblet" info "$out" --json > "$work/info.json"
  /usr/bin/python3 - "$f" "$work/stats.json" "$work/info.json" "$t0" "$t1" "$t2" <<'PY'
import json, sys
name, path, info, t0, t1, t2 = sys.argv[1], sys.argv[2], sys.argv[3], *map(float, sys.argv[4:])
s = json.load(open(path))
bits = " (16-bit)" if json.load(open(info))["version"] in (16, 17) else ""
e = s["error"]
extra = ""
if s["resampled"]:
    o = s["error_vs_original"]
    extra = f" (resampled; vs original polyline {o['max_um']:.2f} / {o['mean_um']:.2f})"
g = s["geometry"]
ends, length = g["endpoint"], g["length_change"]
print(f"| {name} | {s['reference_bytes']/1e6:.2f} MB | {s['fft_bytes']/1e6:.3f} MB | {s['ratio']:.2f}×{bits} | "
      f"{e['max_um']:.2f} / {e['mean_um']:.2f}{extra} | {g['hausdorff_um']:.2f} | "
      f"{ends['max_um']:.2f} / {ends['mean_um']:.2f} | {length['max_um']:.1f} / {length['mean_um']:.1f} "
      f"({length['mean_percent']:.3f} %) | {t1-t0:.2f} | {t2-t1:.2f} |")
PY
done
