#!/usr/bin/python3
"""Turns the rows of scripts/bench_table.sh into bench/results.md and the plot.

Input: JSON lines (one per row, from fiblet_bench_table plus the script's
fields) and Google Benchmark's JSON output. Needs matplotlib (Debian's
python3-matplotlib) for the plot.
"""
import argparse
import json
import os
import platform
import subprocess
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

LABELS = {
    "tck": ".tck float32, parsed by fiblet's TckReader",
    "tck+zstd-3": ".tck + zstd -3 (decompress + parse)",
    "tck+zstd-19": ".tck + zstd -19 (decompress + parse)",
    "float16": "float16 positions (TRX lossy)",
    "sequential": "sequential, no blocks (QFib-style)",
}


def row_name(r):
    if r["row"] == "decode":
        kind = r["label"].replace("fiblet-", "fiblet .fft ")
        return f"{kind}, {r['decoder']}, {int(r['threads'])} thread{'s' if r['threads'] > 1 else ''}"
    return LABELS.get(r["label"], r["label"])


def machine():
    cpu = "unknown CPU"
    flags = set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name") and cpu == "unknown CPU":
                    cpu = line.split(":", 1)[1].strip()
                if line.startswith("flags"):
                    flags = set(line.split(":", 1)[1].split())
    except OSError:
        pass
    simd = ", ".join(x for x in ("avx2", "fma", "avx512f", "avx512bw", "avx512vl") if x in flags) or "none"
    load = os.getloadavg()
    return (f"{cpu}, {os.cpu_count()} logical cores, SIMD: {simd}; {platform.system()} {platform.release()}; "
            f"load average {load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f} (1 / 5 / 15 min) when the table was written")


def fmt(x, digits=3):
    if x is None:
        return "—"
    if x == 0:
        return "0"
    if abs(x) >= 100:
        return f"{x:.0f}"
    return f"{x:.{digits}g}"


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--rows", required=True)
    ap.add_argument("--micro")
    ap.add_argument("--tck", required=True)
    ap.add_argument("--command", required=True)
    ap.add_argument("--md", required=True)
    ap.add_argument("--png", required=True)
    a = ap.parse_args()
    rows = [json.loads(line) for line in open(a.rows) if line.strip()]
    tck = next(r for r in rows if r["label"] == "tck")
    tck_bytes, points = tck["bytes"], tck["points"]

    def mps(r, key):
        return r["points"] / r[key] / 1e6 if r.get(key) else None

    md = []
    md.append("# Rate, distortion and speed\n")
    md.append(f"Tractogram: `{os.path.basename(a.tck)}`, {int(tck['fibers']):,} streamlines, {int(points):,} points, "
              f"{tck_bytes / 2**20:.0f} MiB as float32 `.tck`.  ")
    md.append(f"Machine: {machine()}.  ")
    md.append(f"Command: `{a.command}` ({time.strftime('%Y-%m-%d')}).\n")
    md.append("Decode: every fiber into float32 xyz + offsets in memory (buffers allocated beforehand), best of "
              "several runs, wall clock; in brackets the same per CPU-second of the process (what a quiet machine "
              "would show with one thread). Encode: `fiblet compress -j N` end to end (reading the `.tck`, both "
              "passes, writing the `.fft`), the baselines' conversion in memory. Errors: distance from each input "
              "point to its decoded point. Peak RSS: of the decoding process (encode / decode for fiblet).\n")
    md.append("| row | bytes/point | ratio vs .tck | max error µm | mean error µm | encode M points/s | "
              "decode M points/s | peak RSS MiB |")
    md.append("|---|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        enc = mps(r, "encode_seconds")
        dec, dec_cpu = mps(r, "decode_seconds"), mps(r, "decode_cpu_seconds")
        dec_s = fmt(dec) + (f" ({fmt(dec_cpu)})" if dec_cpu and r.get("threads", 1) == 1 else "")
        rss = r["peak_rss_kib"] / 1024
        rss_s = f"{r['encode_rss_kib'] / 1024:.0f} / {rss:.0f}" if "encode_rss_kib" in r else f"{rss:.0f}"
        md.append(f"| {row_name(r)} | {r['bytes'] / r['points']:.3f} | {tck_bytes / r['bytes']:.2f} | "
                  f"{fmt(r.get('max_error_um', 0))} | {fmt(r.get('mean_error_um', 0))} | {fmt(enc)} | {dec_s} | {rss_s} |")
    md.append("")

    # Goals of the decoding issue, from the rows above.
    def find(decoder=None, threads=1, label="fiblet-8bit"):
        for r in rows:
            if r["row"] == "decode" and r["label"] == label and int(r["threads"]) == threads and \
                    (decoder is None or r["decoder"] == decoder):
                return r
        return None

    default = rows[0]["decoder"] if rows and rows[0]["row"] == "decode" else None
    goals = []

    def goal(text, value, target, unit="", cpu=None):
        if value is None:
            goals.append(f"| {text} | not measured | {target}{unit} | — |")
            return
        extra = f" ({cpu:.2f}{unit} per CPU-second)" if cpu else ""
        goals.append(f"| {text} | {value:.2f}{unit}{extra} | {target}{unit} | {'met' if value >= target else 'missed'} |")

    avx2 = find("lanes-avx2")
    goal("decode, M points/s on one core with AVX2 (lanes-avx2)", mps(avx2, "decode_seconds") if avx2 else None, 300,
         cpu=mps(avx2, "decode_cpu_seconds") if avx2 else None)
    scalar, best = find("scalar"), find(default)
    if scalar and best:
        goal(f"SIMD ({default}) / scalar reference, one thread", scalar["decode_seconds"] / best["decode_seconds"], 4,
             "x", cpu=scalar["decode_cpu_seconds"] / best["decode_cpu_seconds"])
    enc = find(default)
    goal("encode, M points/s per core (`fiblet compress -j 1`)", mps(enc, "encode_seconds") if enc else None, 50)
    two = find(default, 2)
    if best and two:
        goal(f"2 threads / 1 thread ({default})", best["decode_seconds"] / two["decode_seconds"], 1.8, "x")
    if best:
        goal(f"decode ({default}, one thread) / .tck parse", tck["decode_seconds"] / best["decode_seconds"], 5, "x",
             cpu=tck["decode_cpu_seconds"] / best["decode_cpu_seconds"])
    md.append("## Goals\n")
    md.append("| goal | measured | target | |")
    md.append("|---|---:|---:|---|")
    md.extend(goals)
    md.append("")

    if a.micro and os.path.exists(a.micro):
        micro = json.load(open(a.micro))
        md.append("## Micro-benchmarks (Google Benchmark, `build/bench/fiblet_bench`)\n")
        md.append("`DecodeBlocks/*`: the blocks of `small-ifod1.tck` decoded 512 at a time into a buffer that stays "
                  "in the cache (the decoders' own speed); `DecodeBlocksToMemory/*`: all at once into 22 MB; "
                  "`DecodeFile/*`: `decode_fibers_into` from the file. Rates per CPU-second except for the "
                  "threaded rows (wall clock).\n")
        md.append("| benchmark | wall ms | CPU ms | M points/s |")
        md.append("|---|---:|---:|---:|")
        for b in micro.get("benchmarks", []):
            ips = b.get("items_per_second")
            unit = {"ms": 1, "us": 1e-3, "ns": 1e-6}.get(b.get("time_unit", "ns"), 1)
            md.append(f"| {b['name']} | {b['real_time'] * unit:.3g} | {b['cpu_time'] * unit:.3g} | "
                      f"{fmt(ips / 1e6) if ips else '—'} |")
        ctx = micro.get("context", {})
        md.append(f"\n(Google Benchmark: {ctx.get('num_cpus', '?')} CPUs at {ctx.get('mhz_per_cpu', '?')} MHz, "
                  f"load average {', '.join(f'{x:.1f}' for x in ctx.get('load_avg', []))}.)\n")

    with open(a.md, "w") as f:
        f.write("\n".join(md))

    # The plot: decode speed and size against the error (mean to max).
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
    for r in rows:
        name = row_name(r)
        threads = int(r.get("threads", 1))
        dec = mps(r, "decode_seconds")
        emax, emean = r.get("max_error_um", 0), r.get("mean_error_um", 0)
        fiblet = r["row"] == "decode"
        marker = "o" if fiblet else "s"
        face = None if threads == 1 else "none"
        for ax, y in ((axes[0], dec), (axes[1], r["bytes"] / r["points"])):
            if fiblet and ax is axes[1] and threads != 1:
                continue
            line = ax.plot([emean, emax], [y, y], "-", alpha=0.4)[0]
            ax.plot([emax], [y], marker, color=line.get_color(), markerfacecolor=face or line.get_color(),
                    label=name if (ax is axes[0] or not fiblet or True) else None)
            ax.plot([emean], [y], "|", color=line.get_color())
    for ax in axes:
        ax.set_xscale("symlog", linthresh=1)
        ax.set_xlabel("error, µm (tick: mean, marker: max; lossless at 0)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_yscale("log")
    axes[0].set_ylabel("decode, M points/s (wall clock)")
    axes[0].set_title("Decode speed against error (hollow: 2 threads)")
    axes[1].set_ylabel("bytes per point")
    axes[1].set_title("Size against error")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=7)
    fig.tight_layout(rect=(0, 0.22, 1, 1))
    fig.savefig(a.png, dpi=110)


if __name__ == "__main__":
    main()
