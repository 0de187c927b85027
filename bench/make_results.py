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
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from results_sections import replace_section  # noqa: E402

LABELS = {
    "tck": ".tck float32, parsed by fiblet's TckReader",
    "tck-cold": ".tck float32, parsed, read from disk (page cache dropped)",
    "tck+zstd-3": ".tck + zstd -3 (decompress + parse)",
    "tck+zstd-19": ".tck + zstd -19 (decompress + parse)",
    "float16": "float16 positions (TRX lossy)",
    "sequential": "sequential, no blocks (QFib-style)",
}


def row_name(r):
    if r["row"] == "decode":
        label = r["label"].replace("-cold", "")
        kind = {"fiblet-8bit": "fiblet .fft 8-bit", "fiblet-16bit": "fiblet .fft 16-bit",
                "fiblet-zstd": "fiblet .fft + zstd stage"}.get(label, label)
        cold = ", read from disk (page cache dropped)" if r.get("cold") else ""
        return f"{kind}, {r['decoder']}, {int(r['threads'])} thread{'s' if r['threads'] > 1 else ''}{cold}"
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
    for r in rows:  # a cold row has the errors of its warm twin (same file)
        if r.get("cold") and r["row"] == "decode" and "max_error_um" not in r:
            twin = next((t for t in rows if t["label"] == r["label"].replace("-cold", "") and "max_error_um" in t), None)
            if twin:
                r.update({k: twin[k] for k in ("max_error_um", "mean_error_um")})
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
              "several runs, wall clock; in brackets points per CPU-second of the process (all its threads): "
              "on a loaded machine the closer estimate of what a quiet one shows with one thread, and for two "
              "threads the cost of the parallel work (equal to the one-thread figure when splitting costs "
              "nothing). Encode: `fiblet compress -j N` end to end (reading the `.tck` twice, encoding, measuring "
              "the error, writing the `.fft`), the baselines' conversion in memory. Errors: distance from each "
              "input point to its decoded point. Peak RSS: of the decoding process (encode / decode for fiblet). "
              "The zstd rows decode = decompression + the `.tck` parse.\n")
    md.append("| row | bytes/point | ratio vs .tck | max error µm | mean error µm | encode M points/s | "
              "decode M points/s | peak RSS MiB |")
    md.append("|---|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        enc = mps(r, "encode_seconds")
        dec, dec_cpu = mps(r, "decode_seconds"), mps(r, "decode_cpu_seconds")
        dec_s = fmt(dec) + (f" ({fmt(dec_cpu)})" if dec_cpu else "")
        rss = r["peak_rss_kib"] / 1024
        rss_s = f"{r['encode_rss_kib'] / 1024:.0f} / {rss:.0f}" if "encode_rss_kib" in r else f"{rss:.0f}"
        md.append(f"| {row_name(r)} | {r['bytes'] / r['points']:.3f} | {tck_bytes / r['bytes']:.2f} | "
                  f"{fmt(r.get('max_error_um', 0))} | {fmt(r.get('mean_error_um', 0))} | {fmt(enc)} | {dec_s} | {rss_s} |")
    md.append("")

    # Goals of the decoding issue, from the rows above. On a loaded machine
    # (load average above half the cores) wall-clock ratios measure the
    # scheduler: single-thread goals are then judged on CPU time.
    def find(decoder=None, threads=1, label="fiblet-8bit"):
        for r in rows:
            if r["row"] == "decode" and r["label"] == label and int(r["threads"]) == threads and \
                    (decoder is None or r["decoder"] == decoder) and not r.get("cold"):
                return r
        return None

    micro_ips = {}
    if a.micro and os.path.exists(a.micro):
        for b in json.load(open(a.micro)).get("benchmarks", []):
            if b.get("items_per_second"):
                micro_ips[b["name"]] = b["items_per_second"] / 1e6
    # The benchmark itself keeps one or two cores busy: only more than that is other load.
    loaded = os.getloadavg()[1] > 1.5 * (os.cpu_count() or 1)
    default = rows[0]["decoder"] if rows and rows[0]["row"] == "decode" else None
    goals = []

    def goal(text, wall, cpu, cache, target, unit="", judge_cpu=True):
        judged = cpu if (loaded and judge_cpu and cpu is not None) else wall
        verdict = "—" if judged is None else ("met" if judged >= target else "missed")
        if loaded and judge_cpu and cpu is not None:
            verdict += " (on CPU time)"
        f = lambda v: "—" if v is None else f"{v:.2f}{unit}"
        goals.append(f"| {text} | {f(wall)} | {f(cpu)} | {f(cache)} | {target}{unit} | {verdict} |")

    avx2, scalar, best, two = find("lanes-avx2"), find("scalar"), find(default), find(default, 2)
    if avx2:
        goal("decode, M points/s, one core, AVX2 (lanes-avx2)", mps(avx2, "decode_seconds"),
             mps(avx2, "decode_cpu_seconds"), micro_ips.get("DecodeBlocks/lanes-avx2"), 300)
    if scalar and best:
        mb, ms = micro_ips.get(f"DecodeBlocks/{default}"), micro_ips.get("DecodeBlocks/scalar")
        goal(f"SIMD ({default}) / scalar reference, one thread", scalar["decode_seconds"] / best["decode_seconds"],
             scalar["decode_cpu_seconds"] / best["decode_cpu_seconds"], mb / ms if mb and ms else None, 4, "x")
    if best:
        goal("encode, M points/s, one core (`fiblet compress -j 1`; in cache: `EncodeFibers`)",
             mps(best, "encode_seconds"), None, micro_ips.get("EncodeFibers"), 50, judge_cpu=False)
    if best and two:
        # CPU column: 2 x (1-thread CPU time / 2-thread CPU time), the speed-up
        # two idle cores would give if nothing but the split cost (no memory
        # bandwidth limit): a projection, not a measurement.
        goal(f"2 threads / 1 thread ({default}); CPU column: projection", best["decode_seconds"] / two["decode_seconds"],
             2 * best["decode_cpu_seconds"] / two["decode_cpu_seconds"], None, 1.8, "x", judge_cpu=False)
    if best:
        mt = micro_ips.get("TckParse")
        mb = micro_ips.get(f"DecodeBlocksToMemory/{default}")
        goal(f"decode ({default}, one thread) / .tck parse (cache column: to memory)",
             tck["decode_seconds"] / best["decode_seconds"], tck["decode_cpu_seconds"] / best["decode_cpu_seconds"],
             mb / mt if mb and mt else None, 5, "x")
        cold_t = next((r for r in rows if r["label"] == "tck-cold"), None)
        cold_f = next((r for r in rows if r["label"] == "fiblet-8bit-cold"), None)
        if cold_t and cold_f:
            goal("the same, both read from disk (page cache dropped)", cold_t["decode_seconds"] / cold_f["decode_seconds"],
                 None, None, 5, "x", judge_cpu=False)
    md.append("## Goals\n")
    md.append("Wall clock and CPU time: from the table above; in cache: the micro-benchmarks below (blocks decoded "
              "512 at a time into an L2-resident buffer, per CPU-second)." +
              (f" The machine was loaded (load average {os.getloadavg()[1]:.1f} on {os.cpu_count()} cores): "
               "single-thread goals are judged on CPU time, the thread goal cannot be measured." if loaded else "") +
              "\n")
    md.append("| goal | wall clock | CPU time | in cache | target | |")
    md.append("|---|---:|---:|---:|---:|---|")
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

    # The sections other scripts write (bench_pipeline.sh, bench_front.sh) follow.
    doc = "\n".join(md)
    for name in ("results-pipeline.md", "results-front.md"):
        section = os.path.join(os.path.dirname(os.path.abspath(a.md)), name)
        if os.path.exists(section):
            doc = replace_section(doc, open(section).read())
    with open(a.md, "w") as f:
        f.write(doc)

    # The plot: decode speed (one thread) and size against the error, the
    # line from the mean error (tick) to the max (marker).
    fig, axes = plt.subplots(1, 2, figsize=(13, 6))
    colors = plt.get_cmap("tab20").colors
    speed_key = "decode_cpu_seconds" if loaded else "decode_seconds"
    seen_sizes = set()
    for i, r in enumerate(r for r in rows if int(r.get("threads", 1)) == 1):
        color = colors[i % len(colors)]
        fiblet = r["row"] == "decode"
        emax, emean = r.get("max_error_um", 0), r.get("mean_error_um", 0)
        marker = "o" if fiblet else "s"
        name = row_name(r)
        y = mps(r, speed_key)
        axes[0].plot([emean, emax], [y, y], "-", color=color, alpha=0.5)
        axes[0].plot([emax], [y], marker, color=color, label=name)
        axes[0].plot([emean], [y], "|", color=color)
        size_key = (r["label"].replace("-cold", ""), round(r["bytes"] / r["points"], 3))
        if size_key not in seen_sizes:
            seen_sizes.add(size_key)
            size_name = name.split(",")[0] if fiblet else name
            yb = r["bytes"] / r["points"]
            axes[1].plot([emean, emax], [yb, yb], "-", color=color, alpha=0.5)
            axes[1].plot([emax], [yb], marker, color=color)
            axes[1].plot([emean], [yb], "|", color=color)
            axes[1].annotate(size_name, (emax, yb), textcoords="offset points", xytext=(6, 3), fontsize=7)
    for ax in axes:
        ax.set_xscale("symlog", linthresh=1)
        ax.set_xlim(-0.3, 60)
        ax.set_xlabel("error, µm (tick: mean, marker: max; lossless at 0)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_yscale("log")
    axes[0].set_ylabel("decode, M points/s" + (" per CPU-second (machine loaded)" if loaded else " (wall clock)"))
    axes[0].set_title("Decode speed against error, one thread")
    axes[1].set_ylabel("bytes per point")
    axes[1].set_title("Size against error")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=7)
    fig.tight_layout(rect=(0, 0.2, 1, 1))
    fig.savefig(a.png, dpi=110)


if __name__ == "__main__":
    main()
