#!/usr/bin/python3
"""Compress run time against error: fiblet at every effort and the peers, in one interleaved run.

Every encoder compresses the same .tck on one pinned core, round after round
(round r runs every encoder once, in the same order), so a slow spell of the
machine falls on all of them alike; the figure is the median of the rounds.
Then each output is measured against the input, pointwise:
  - .fft (fiblet, the official Fiblets encoder): tests/tools/exact_error.cpp,
    the float64 reference decoder and fiblet's float32 decoder;
  - QFib: decompressed by QFib itself, then compared point by point here;
  - zstd: lossless.
Peers are binaries built out of tree (never part of fiblet); one that is not
given is skipped with a note, never estimated.
  FIBLET_OFFICIAL_ENCODER  the official Fiblets encoder: ENC IN.tck OUT.fft
  FIBLET_QFIB              QFib's qfib program: qfib IN.tck OUT.qfib, qfib IN.qfib OUT.tck
zstd is taken from PATH. Writes front.json, front.md and front.png into --out.
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_results import machine  # noqa: E402  (the CPU, its SIMD and the load, as bench/results.md words it)


def read_tck(path):
    """The points of a float32 little-endian .tck, and where each streamline ends."""
    with open(path, "rb") as f:
        head = b""
        while not head.endswith(b"END\n"):
            line = f.readline()
            if not line:
                raise ValueError(f"{path}: no END line")
            head += line
    offset = int(re.search(rb"\nfile:\s*\.\s+(\d+)", head).group(1))
    if b"Float32LE" not in head:
        raise ValueError(f"{path}: only Float32LE .tck files are measured here")
    data = np.fromfile(path, dtype="<f4", offset=offset).reshape(-1, 3)
    sep = np.isnan(data[:, 0]) | np.isinf(data[:, 0])
    return data, sep


def pointwise_error(decoded_tck, input_tck):
    """Max and mean distance (mm) between the i-th points of two .tck files of the same layout."""
    a, sa = read_tck(decoded_tck)
    b, sb = read_tck(input_tck)
    if a.shape != b.shape or not np.array_equal(sa, sb):
        raise ValueError(f"{decoded_tck}: not the layout of {input_tck}")
    keep = ~sa
    d = np.sqrt(((a[keep].astype(np.float64) - b[keep].astype(np.float64)) ** 2).sum(axis=1))
    return float(d.max()), float(d.mean())


class Encoder:
    def __init__(self, name, kind, command, ext, group, effort=None):
        self.name, self.kind, self.command, self.ext, self.group, self.effort = name, kind, command, ext, group, effort
        self.seconds = []


def encoders(args, work):
    fiblet = [args.fiblet, "compress", "-q", "-f"]
    out = []

    def f(name, extra, group, effort=None, ext="fft"):
        threads = [] if "-j" in extra else ["-j", "1"]
        out.append(Encoder(name, "fiblet", lambda i, o, e=threads + extra: fiblet + e + [i, "-o", o], ext, group, effort))

    f("fiblet default", [], "fiblet default")
    for e in range(args.max_effort + 1):
        f(f"fiblet --effort {e}", ["--bits", "8", "--effort", str(e)], "fiblet 8-bit", e)
    for e in (0, 1):
        f(f"fiblet --bits 16 --effort {e}", ["--bits", "16", "--effort", str(e)], "fiblet 16-bit", e)
    f("fiblet --zstd", ["--zstd"], "fiblet --zstd", ext="fftz")
    f("fiblet -j 2", ["-j", "2"], "fiblet 2 threads")
    if args.baseline:  # an earlier build: before and after in the same run
        before = [args.baseline, "compress", "-q", "-f", "-j", "1"]
        label = args.baseline_label or "before"
        out.append(Encoder(f"fiblet default ({label})", "fiblet", lambda i, o: before + [i, "-o", o], "fft",
                           f"fiblet {label}"))
        out.append(Encoder(f"fiblet --effort 0 --bits 8 ({label})", "fiblet",
                           lambda i, o: before + ["--effort", "0", "--bits", "8", i, "-o", o], "fft", f"fiblet {label}"))
    official = os.environ.get("FIBLET_OFFICIAL_ENCODER")
    if official:
        out.append(Encoder("official Fiblets", "official", lambda i, o: [official, i, o], "fft", "official"))
    qfib = os.environ.get("FIBLET_QFIB")
    if qfib:
        out.append(Encoder("QFib 8-bit", "qfib", lambda i, o: [qfib, i, o], "qfib", "QFib"))
    if shutil.which("zstd"):
        out.append(Encoder("zstd -3", "zstd", lambda i, o: ["zstd", "-3", "-T1", "-q", "-f", i, "-o", o], "zst", "zstd"))
    out.append(Encoder("cp", "copy", lambda i, o: ["cp", i, o], "tck", "cp"))
    skipped = []
    if not official:
        skipped.append("official Fiblets encoder: FIBLET_OFFICIAL_ENCODER not set")
    if not qfib:
        skipped.append("QFib: FIBLET_QFIB not set")
    if not shutil.which("zstd"):
        skipped.append("zstd: not on PATH")
    return out, skipped


def run_timed(cmd, core):
    # Pinned to one core; "-j 2" runs get the core and the next one.
    cores = f"{core},{(core + 1) % os.cpu_count()}" if "-j" in cmd and cmd[cmd.index("-j") + 1] == "2" else str(core)
    full = ["taskset", "-c", cores] + cmd if shutil.which("taskset") else cmd
    t0 = time.perf_counter()
    r = subprocess.run(full, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    dt = time.perf_counter() - t0
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {r.returncode}: {r.stderr.decode(errors='replace')[-500:]}")
    return dt


def measure_error(enc, output, args, work):
    """(float64 max, mean, float32 max, mean) in um; None where not measurable."""
    if enc.kind in ("zstd", "copy"):
        return 0.0, 0.0, 0.0, 0.0
    if enc.kind == "qfib":
        decoded = os.path.join(work, "qfib-decoded.tck")
        subprocess.run([os.environ["FIBLET_QFIB"], output, decoded], check=True, stdout=subprocess.DEVNULL)
        mx, mean = pointwise_error(decoded, args.tck)
        os.unlink(decoded)
        return mx * 1e3, mean * 1e3, mx * 1e3, mean * 1e3
    src = output
    if output.endswith(".fftz"):
        src = os.path.join(work, "unz.fft")
        subprocess.run([args.fiblet, "extract", "-q", "-f", output, "-o", src], check=True)  # the same blocks, unzipped
    r = subprocess.run([args.exact_error, src, args.tck], check=True, capture_output=True, text=True).stdout
    m = re.search(r"float64 max/mean ([\d.]+) / ([\d.]+) um.*fiblet decoder max/mean ([\d.]+) / ([\d.]+) um", r)
    return tuple(float(x) for x in m.groups())


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--tck", help="the tractogram (required unless --replot)")
    p.add_argument("--replot", help="draw front.png and front.md again from a front.json")
    p.add_argument("--fiblet")
    p.add_argument("--exact-error", help="build/tests/fiblet_exact_error")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--core", type=int, default=1, help="the core every encoder is pinned to")
    p.add_argument("--max-effort", type=int, default=3)
    p.add_argument("--out", required=True)
    p.add_argument("--command", default="", help="the command line recorded beside the figures")
    p.add_argument("--baseline", help="an earlier fiblet binary, measured in the same run")
    p.add_argument("--baseline-label", help="its name in the table (e.g. a commit)")
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    if args.replot:
        with open(args.replot) as f:
            result = json.load(f)
        cp = next((r["seconds"] for r in result["rows"] if r["encoder"] == "cp"), None)
        write_markdown(result, cp, os.path.join(args.out, "front.md"))
        plot(result, os.path.join(args.out, "front.png"))
        return
    if not (args.tck and args.fiblet and args.exact_error):
        p.error("--tck, --fiblet and --exact-error are required")
    points = int(np.count_nonzero(~read_tck(args.tck)[1]))
    in_bytes = os.path.getsize(args.tck)
    work = tempfile.mkdtemp(prefix="fiblet-front-")
    try:
        encs, skipped = encoders(args, work)
        outputs = {e.name: os.path.join(work, re.sub(r"[^a-z0-9]+", "-", e.name.lower()) + "." + e.ext) for e in encs}
        # The input in the page cache before the first round.
        with open(args.tck, "rb") as f:
            while f.read(1 << 24):
                pass
        for r in range(args.rounds):
            for e in encs:
                e.seconds.append(run_timed(e.command(args.tck, outputs[e.name]), args.core))
            print(f"round {r + 1}/{args.rounds} done", file=sys.stderr)
        rows = []
        for e in encs:
            sec = statistics.median(e.seconds)
            f64max, f64mean, f32max, f32mean = measure_error(e, outputs[e.name], args, work)
            rows.append({"encoder": e.name, "group": e.group, "effort": e.effort, "seconds": sec,
                         "mpoints_per_s": points / sec / 1e6, "ratio": in_bytes / os.path.getsize(outputs[e.name]),
                         "bytes": os.path.getsize(outputs[e.name]),
                         "max_um_f64": f64max, "mean_um_f64": f64mean, "max_um_f32": f32max, "mean_um_f32": f32mean})
    finally:
        shutil.rmtree(work, ignore_errors=True)
    cp = next((r["seconds"] for r in rows if r["encoder"] == "cp"), None)
    result = {"tck": os.path.basename(args.tck), "points": points, "rounds": args.rounds, "machine": machine(),
              "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "command": args.command,
              "skipped": skipped, "rows": rows}
    with open(os.path.join(args.out, "front.json"), "w") as f:
        json.dump(result, f, indent=1)
    write_markdown(result, cp, os.path.join(args.out, "front.md"))
    plot(result, os.path.join(args.out, "front.png"))


def write_markdown(result, cp, path):
    ref = next((r for r in result["rows"] if r["encoder"] == "official Fiblets"), None)
    lines = [f"{result['tck']} ({result['points'] / 1e6:.1f} M points), {result['machine']}, "
             f"one pinned core, median of {result['rounds']} interleaved rounds, {result['date']}.", ""]
    if result["command"]:
        lines += [f"Command: `{result['command']}`", ""]
    lines += ["| encoder | M points/s | time vs `cp` | ratio | max / mean µm (float64 decode) "
              "| max / mean µm (fiblet float32 decode) | vs official: speed, max, mean |",
              "|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        vs = "—"
        if ref and r["encoder"] != ref["encoder"] and ref["max_um_f64"] > 0:
            vs = (f"{r['mpoints_per_s'] / ref['mpoints_per_s']:.2f}× / {r['max_um_f64'] / ref['max_um_f64']:.2f}× / "
                  f"{r['mean_um_f64'] / ref['mean_um_f64']:.2f}×")
        lines.append(f"| {r['encoder']} | {r['mpoints_per_s']:.2f} | {r['seconds'] / cp:.1f}× | {r['ratio']:.2f}× | "
                     f"{r['max_um_f64']:.2f} / {r['mean_um_f64']:.2f} | {r['max_um_f32']:.2f} / {r['mean_um_f32']:.2f} | {vs} |")
    for s in result["skipped"]:
        lines.append(f"\nSkipped: {s}.")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def plot(result, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in result["rows"] if r["group"] not in ("cp", "fiblet 2 threads")]
    colours = {"fiblet 8-bit": "tab:blue", "fiblet default": "tab:red", "fiblet 16-bit": "tab:cyan",
               "fiblet 2 threads": "tab:pink", "fiblet before": "tab:olive",
               "fiblet --zstd": "tab:purple", "official": "tab:orange", "QFib": "tab:green", "zstd": "tab:gray"}
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    for ax, key, title in ((axes[0], "max_um_f64", "max error"), (axes[1], "mean_um_f64", "mean error")):
        for r in rows:  # lossless peers: a line at their speed
            if r[key] == 0:
                ax.axvline(r["mpoints_per_s"], color=colours.get(r["group"], "k"), linestyle="--", linewidth=1)
                ax.annotate(f"{r['encoder']} (lossless, {r['ratio']:.2f}×)", (r["mpoints_per_s"], 0.02),
                            xycoords=("data", "axes fraction"), rotation=90, fontsize=7, xytext=(-10, 0),
                            textcoords="offset points")
        for group in dict.fromkeys(r["group"] for r in rows if r[key] > 0):
            g = [r for r in rows if r["group"] == group]
            xs = [r["mpoints_per_s"] for r in g]
            ys = [r[key] for r in g]
            default = group == "fiblet default"  # drawn on top: it is one of the efforts too
            ax.scatter(xs, ys, s=[(30 if default else 12) * r["ratio"] for r in g], color=colours.get(group, "k"),
                       label=group, alpha=0.9, edgecolors="k", linewidths=0.5, marker="*" if default else "o",
                       zorder=3 if default else 2)
            if len(g) > 1:
                ax.plot(xs, ys, color=colours.get(group, "k"), linewidth=1)
            for r in g:
                label = f"e{r['effort']}" if r["effort"] is not None else ""
                if label:
                    ax.annotate(label, (r["mpoints_per_s"], r[key]), fontsize=7, xytext=(3, 3),
                                textcoords="offset points")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("compress, M points/s (one core)")
        ax.set_ylabel(f"{title}, µm (float64 decode vs input)")
        ax.set_title(f"{title}: lower right is better")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8, loc="best")
    # Wrapped: the machine's description (CPU, SIMD, kernel, load) is longer than the figure.
    title = f"{result['tck']}: {result['machine']} (marker area ∝ compression ratio)"
    fig.suptitle("\n".join(textwrap.wrap(title, 160)), fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
