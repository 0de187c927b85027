#!/usr/bin/python3
"""Loading a tractogram in Python: fiblet.load of the .fft versus
nibabel.streamlines.load of the .tck it was made from.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_load.py TCK FFT [--repeat N] [--json OUT]

Both files are read once before timing (warm page cache), so the figures
compare decoding with parsing, not disk speed. Each load is repeated and the
best and median wall times are reported; the speed-up uses the medians.
Usually run through scripts/bench_python.sh.
"""
import argparse
import gc
import json
import os
import platform
import resource
import statistics
import time

import nibabel as nib
import numpy as np

import fiblet


def cpu_seconds():
    r = resource.getrusage(resource.RUSAGE_SELF)  # all threads of the process
    return r.ru_utime + r.ru_stime


def timed(fn, repeat):
    times, cpu, result = [], [], None
    for _ in range(repeat):
        result = None
        gc.collect()
        c0, t0 = cpu_seconds(), time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
        cpu.append(cpu_seconds() - c0)
    return times, cpu, result


def warm(path):
    with open(path, "rb") as f:
        while f.read(1 << 24):
            pass


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("tck")
    ap.add_argument("fft")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--json", help="also write the results here")
    a = ap.parse_args()
    warm(a.tck), warm(a.fft)

    cases = {
        "nibabel.streamlines.load(.tck)": lambda: nib.streamlines.load(a.tck).streamlines,
        "fiblet.load(.fft)": lambda: fiblet.load(a.fft),
        "fiblet.load_tractogram(.fft)": lambda: fiblet.load_tractogram(a.fft).streamlines,
    }
    rows = {}
    for name, fn in cases.items():
        times, cpu, result = timed(fn, a.repeat if "fiblet" in name else max(2, a.repeat // 2))
        points = len(result.points) if isinstance(result, fiblet.Streamlines) else len(result.get_data())
        rows[name] = {"best_s": min(times), "median_s": statistics.median(times), "runs": len(times),
                      "median_cpu_s": statistics.median(cpu),
                      "points": points, "mpoints_per_s": points / statistics.median(times) / 1e6}
        del result
    base = rows["nibabel.streamlines.load(.tck)"]["median_s"]
    for r in rows.values():
        r["speedup_vs_nibabel"] = base / r["median_s"]

    info = fiblet.info(a.fft)
    print(f"{os.path.basename(a.tck)}: {info['fibers']} fibers, {info['points']} points; "
          f".tck {os.path.getsize(a.tck) / 1e6:.1f} MB, .fft {os.path.getsize(a.fft) / 1e6:.1f} MB")
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
          f"fiblet {fiblet.__version__} (block decoder: {fiblet._fiblet.block_decoder}), "
          f"nibabel {nib.__version__}, numpy {np.__version__}; load average {os.getloadavg()[0]:.1f}")
    print()
    print("| load | median s | best s | CPU s (all threads) | M points/s | speed-up vs nibabel |")
    print("|---|---|---|---|---|---|")
    for name, r in rows.items():
        print(f"| `{name}` | {r['median_s']:.3f} | {r['best_s']:.3f} | {r['median_cpu_s']:.3f} | "
              f"{r['mpoints_per_s']:.1f} | {r['speedup_vs_nibabel']:.1f}x |")
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"tck": a.tck, "fft": a.fft, "fibers": info["fibers"], "points": info["points"],
                       "results": rows}, f, indent=1)


if __name__ == "__main__":
    main()
