#!/usr/bin/python3
"""fiblet.load(FFT, roi=sphere) against fiblet.load(FFT): spheres at the
origin of several radii, each call alternated with the full load in one
process, so that both see the same machine state.

    PYTHONPATH=build/python /usr/bin/python3 bench/roi_speed.py FFT [--radii 1,6,10,...] [--rounds N] [--threads T]

Prints, per radius, the fibers kept and the median wall and CPU time
(all threads) of the rounds, each as a ratio to the full load's median.
"""
import argparse
import resource
import statistics
import time

import fiblet


def cpu_seconds():
    r = resource.getrusage(resource.RUSAGE_SELF)  # all threads of the process
    return r.ru_utime + r.ru_stime


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("fft")
    ap.add_argument("--radii", default="1,6,10,12,15,20,30,45", help="sphere radii in mm, comma-separated")
    ap.add_argument("--rounds", type=int, default=9)
    ap.add_argument("--threads", type=int, default=None, help="fiblet.load's threads (default: all cores)")
    args = ap.parse_args()
    radii = [float(r) for r in args.radii.split(",")]
    calls = [("full", None)] + [(f"r = {r:g} mm", (0.0, 0.0, 0.0, r)) for r in radii]
    wall = {name: [] for name, _ in calls}
    cpu = {name: [] for name, _ in calls}
    kept = {}
    for _ in range(args.rounds):
        for name, roi in calls:
            c0, t0 = cpu_seconds(), time.perf_counter()
            s = fiblet.load(args.fft, roi=roi, threads=args.threads)
            wall[name].append(time.perf_counter() - t0)
            cpu[name].append(cpu_seconds() - c0)
            kept[name] = len(s)
            del s  # each call starts with the same memory free (the last result would hold 552 MB)
    full_wall, full_cpu = statistics.median(wall["full"]), statistics.median(cpu["full"])
    print(f"| call | fibers | wall ms | vs full | CPU ms | vs full |")
    print(f"|---|---:|---:|---:|---:|---:|")
    for name, _ in calls:
        w, c = statistics.median(wall[name]), statistics.median(cpu[name])
        print(f"| {name} | {kept[name]} | {w * 1e3:.1f} | {w / full_wall:.2f}x | {c * 1e3:.1f} | {c / full_cpu:.2f}x |")


if __name__ == "__main__":
    main()
