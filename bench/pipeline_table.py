#!/usr/bin/python3
"""Every row of the parallel-pipeline table (issue 14) from one run, with the
machine's load: decompress and compress scaling (quiet and with a competing
`yes > /dev/null`), the machine's own floor for 2 threads vs 1, decompress to a file against `cp`, compress speed,
fiblet.load against numpy.fromfile of the .tck, 16-bit files against 8-bit
ones (fiblet.load) and against `cp` (decompress, 1 thread, with the .fftz),
selection of 10 % of the blocks against a full decode, the block index's
share of the file, and the 16-bit size and error.

    /usr/bin/python3 bench/pipeline_table.py --build BUILD --tck TCK [--repeat N] [--json OUT]

Usually run through scripts/bench_pipeline.sh. Outputs go to a tmpfs
(/dev/shm) when there is one, page cache warm: the figures compare CPU work,
not disks. Each timing is the median of N runs (wall clock); CPU time
(user + sys, all threads) is shown next to it, since on a shared 2-core
machine the wall time of a 2-thread run depends on the other load.
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import resource


def load():
    return os.getloadavg()


def timed(cmd, repeat, env=None, before=None):
    """Median wall and CPU seconds of `cmd` over `repeat` runs."""
    walls, cpus = [], []
    for _ in range(repeat):
        if before:
            before()
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
        walls.append(time.perf_counter() - t0)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
    return statistics.median(walls), statistics.median(cpus)


def json_of(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


class Busy:
    """A competing CPU-bound process (`yes > /dev/null`) on one core."""

    def __enter__(self):
        self.p = subprocess.Popen(["yes"], stdout=subprocess.DEVNULL)
        time.sleep(0.5)
        return self

    def __exit__(self, *a):
        self.p.kill()
        self.p.wait()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", required=True)
    ap.add_argument("--tck", required=True)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--json")
    ap.add_argument("--skip-select", action="store_true", help="leave out the selection rows (Google Benchmark, slow)")
    a = ap.parse_args()
    cli = os.path.join(a.build, "bin", "fiblet")
    table = os.path.join(a.build, "bench", "fiblet_bench_table")
    tmp_root = "/dev/shm" if os.path.isdir("/dev/shm") else None
    work = tempfile.mkdtemp(prefix="fiblet-pipeline-", dir=tmp_root)
    R = a.repeat
    rows, res = [], {"load_start": load()}
    try:
        tck = os.path.join(work, "in.tck")
        shutil.copyfile(a.tck, tck)
        tck_bytes = os.path.getsize(tck)
        fft = os.path.join(work, "in.fft")
        fftz = os.path.join(work, "in.fftz")
        subprocess.run([cli, "compress", tck, "-o", fft, "-f", "-q"], check=True)
        subprocess.run([cli, "compress", tck, "-o", fftz, "-f", "-q", "--zstd"], check=True)
        info = json_of([table, "decode", fft, "--threads", "1", "--repeat", "1"])
        points = info["points"]

        # Decompress in memory, 1 vs 2 threads (decode_fibers_into, buffers touched beforehand).
        d = {t: json_of([table, "decode", fft, "--threads", str(t), "--repeat", str(R)]) for t in (1, 2)}
        res["decode_mem_s"] = {t: d[t]["decode_seconds"] for t in d}
        res["decode_mem_cpu_s"] = {t: d[t]["decode_cpu_seconds"] for t in d}
        # What 2 threads can do at all on this machine, for the same output size
        # (bench_table.cpp floor): register-only work, writing memory faulted in
        # beforehand, and fresh memory (4 kB pages, MADV_HUGEPAGE).
        res["floor"] = {t: json_of([table, "floor", fft, "--threads", str(t), "--repeat", str(R)]) for t in (1, 2)}
        # Decompress to a .tck file, 1 and 2 threads, and cp of the .tck, same tmpfs.
        out = os.path.join(work, "out.tck")
        rm = lambda: os.path.exists(out) and os.remove(out)
        res["decompress_file"] = {t: timed([cli, "decompress", fft, "-o", out, "-f", "-q", "-j", str(t)], R, before=rm)
                                  for t in (1, 2)}
        res["decompress_fftz_file"] = {t: timed([cli, "decompress", fftz, "-o", out, "-f", "-q", "-j", str(t)], R,
                                                before=rm) for t in (1, 2)}
        res["cp"] = timed(["cp", tck, out], R, before=rm)
        rm()

        # Compress 1 vs 2 threads, quiet and busy.
        o = os.path.join(work, "c.fft")
        res["compress"] = {t: timed([cli, "compress", tck, "-o", o, "-f", "-q", "-j", str(t)], R) for t in (1, 2)}
        with Busy():
            res["load_busy"] = load()
            res["compress_busy"] = {t: timed([cli, "compress", tck, "-o", o, "-f", "-q", "-j", str(t)], R)
                                    for t in (1, 2)}

        # 16-bit size and error; its decompress, 1 thread (and the .fftz's) vs cp.
        fft16 = os.path.join(work, "b16.fft")
        c16 = json_of([cli, "compress", tck, "-o", fft16, "-f", "--json", "--bits", "16"])
        res["bits16"] = {"ratio": tck_bytes / c16["output_bytes"], "max_error_um": c16["max_error_um"]}
        c8 = json_of([cli, "compress", tck, "-o", os.path.join(work, "b8.fft"), "-f", "--json"])
        res["bits8"] = {"ratio": tck_bytes / c8["output_bytes"], "max_error_um": c8["max_error_um"]}
        res["decompress16_file"] = timed([cli, "decompress", fft16, "-o", out, "-f", "-q", "-j", "1"], R, before=rm)
        rm()

        # fiblet.load vs numpy.fromfile, and of the 16-bit file (one Python process, the files warm).
        py = f"""
import json, os, statistics, time, numpy as np, fiblet
def med(f, n):
    ts = []
    for _ in range(n):
        t0 = time.perf_counter(); r = f(); ts.append(time.perf_counter() - t0); del r
    return statistics.median(ts)
tck, fft, fft16, n = {tck!r}, {fft!r}, {fft16!r}, {R}
np.fromfile(tck, dtype=np.uint8); fiblet.load(fft); fiblet.load(fft16)
print(json.dumps({{"fromfile": med(lambda: np.fromfile(tck, dtype="<f4"), n),
                  "load": med(lambda: fiblet.load(fft), n),
                  "load16": med(lambda: fiblet.load(fft16), n)}}))
"""
        env = dict(os.environ, PYTHONPATH=os.path.join(a.build, "python"))
        res["python"] = {}
        for mode in ("huge", "populate"):
            env["FIBLET_PY_BUFFER"] = mode
            res["python"][mode] = json.loads(subprocess.run(["/usr/bin/python3", "-c", py], env=env, check=True,
                                                            capture_output=True, text=True).stdout)


        # Selection of 10 % of the blocks vs a full decode; the index's size (select_bench.cpp).
        if not a.skip_select:
            bj = os.path.join(work, "select.json")
            env = dict(os.environ, FIBLET_BENCH_DATA=os.path.dirname(os.path.abspath(a.tck)))
            subprocess.run([os.path.join(a.build, "bench", "fiblet_bench"),
                            "--benchmark_filter=^BM_Select(FullDecode/0|Everything/0|IndexLoad|Query/(RegionBlocks|Frustum|RegionFibers)/10)$",
                            "--benchmark_repetitions=3", "--benchmark_report_aggregates_only=true",
                            f"--benchmark_out={bj}", "--benchmark_out_format=json"],
                           env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            runs = {b["run_name"]: b for b in json.load(open(bj))["benchmarks"] if b.get("aggregate_name") == "median"}
            full = min(runs["BM_SelectFullDecode/0"]["cpu_time"], runs["BM_SelectEverything/0"]["cpu_time"])
            res["select"] = {k.replace("BM_SelectQuery/", ""): {"pct_of_full": 100 * v["cpu_time"] / full,
                                                                "kept_pct": v.get("kept_pct")}
                             for k, v in runs.items() if k.startswith("BM_SelectQuery/")}
            res["index_pct"] = runs["BM_SelectIndexLoad"]["index_pct_of_file"]
    finally:
        shutil.rmtree(work, ignore_errors=True)
    res["load_end"] = load()

    # The table.
    dm, df, dz, cp = res["decode_mem_s"], res["decompress_file"], res["decompress_fftz_file"], res["cp"]
    cq, cb = res["compress"], res["compress_busy"]
    f = lambda x: f"{x:.2f}"
    rows.append(("decompress `.fft` → memory, 2 threads vs 1",
                 f"**{dm[1] / dm[2]:.2f}×** ({f(dm[1])} s → {f(dm[2])} s; CPU {f(res['decode_mem_cpu_s'][1])} → {f(res['decode_mem_cpu_s'][2])} s)",
                 "≥ 1.8×"))
    fl = res["floor"]
    fr = lambda k: f"{fl[1][k + '_seconds'] / fl[2][k + '_seconds']:.2f}×"
    rows.append(("floor: the same 2 threads vs 1 on this machine",
                 f"compute {fr('compute')}; writing {fl[1]['bytes'] / 1e6:.0f} MB: faulted-in memory {fr('touched')} "
                 f"({f(fl[1]['touched_seconds'])} s → {f(fl[2]['touched_seconds'])} s), fresh 4 kB pages {fr('fresh')} "
                 f"({f(fl[1]['fresh_seconds'])} s → {f(fl[2]['fresh_seconds'])} s), fresh huge pages {fr('fresh_huge')} "
                 f"({f(fl[1]['fresh_huge_seconds'])} s → {f(fl[2]['fresh_huge_seconds'])} s)", "—"))
    rows.append(("decompress `.fft` → `.tck` file, 2 threads vs 1",
                 f"{df[1][0] / df[2][0]:.2f}× ({f(df[1][0])} s → {f(df[2][0])} s; CPU {f(df[1][1])} → {f(df[2][1])} s); "
                 f"`.fftz` {dz[1][0] / dz[2][0]:.2f}×", "—"))
    rows.append(("decompress `.fft` → `.tck` file, 2 threads, vs `cp` of the `.tck`",
                 f"**{df[2][0] / cp[0]:.2f}×** (cp {f(cp[0])} s)", "≤ 1.2×"))
    rows.append(("compress, 2 threads vs 1, quiet",
                 f"**{cq[1][0] / cq[2][0]:.2f}×** ({f(cq[1][0])} s → {f(cq[2][0])} s; CPU {f(cq[1][1])} → {f(cq[2][1])} s)",
                 "≥ 1.8×"))
    rows.append(("compress, 2 threads vs 1, `yes > /dev/null` running",
                 f"**{cb[1][0] / cb[2][0]:.2f}×** ({f(cb[1][0])} s → {f(cb[2][0])} s; load {res['load_busy'][0]:.1f})",
                 "never < 1×"))
    rows.append(("compress, 1 thread, default effort",
                 f"{points / cq[1][0] / 1e6:.1f} M points/s ({cq[1][0] / cp[0]:.1f}× `cp`)",
                 "≥ 50 M points/s (≤ 5× `cp`)"))
    p = res["python"]
    rows.append(("`fiblet.load` of the `.fft` vs `numpy.fromfile` of the `.tck`",
                 f"**{p['huge']['load'] / p['huge']['fromfile']:.2f}×** ({f(p['huge']['load'])} s vs {f(p['huge']['fromfile'])} s; "
                 f"MAP_POPULATE instead of huge pages: {p['populate']['load'] / p['populate']['fromfile']:.2f}×)",
                 "≤ 1.0×"))
    rows.append(("`fiblet.load` of the 16-bit `.fft` vs the 8-bit one",
                 f"**{p['huge']['load16'] / p['huge']['load']:.2f}×** ({f(p['huge']['load16'])} s vs {f(p['huge']['load'])} s)",
                 "≤ 1.5×"))
    d16 = res["decompress16_file"]
    rows.append(("decompress a 16-bit `.fft` / a `.fftz` → `.tck` file, 1 thread, vs `cp`",
                 f"**{d16[0] / cp[0]:.2f}× / {dz[1][0] / cp[0]:.2f}×** ({f(d16[0])} s / {f(dz[1][0])} s; cp {f(cp[0])} s)",
                 "≤ 1.5×"))
    if "select" in res:
        s = res["select"]
        rows.append(("selection of 10 % of the blocks vs a full decode (one thread, CPU)",
                     "; ".join(f"{k.replace('/10', '')} {v['pct_of_full']:.1f} %" for k, v in sorted(s.items())), "≤ 15 %"))
        rows.append(("block index, share of the file", f"{res['index_pct']:.2f} % (8-bit ratio {res['bits8']['ratio']:.2f}×)",
                     "≤ 1 %"))
    rows.append(("`--bits 16` size", f"{res['bits16']['ratio']:.2f}× ({res['bits16']['max_error_um']:.2f} µm max)",
                 "≥ 5.94× at ≤ 0.73 µm"))

    print(f"{os.path.basename(a.tck)}: {points / 1e6:.1f} M points, {tck_bytes / 1e6:.0f} MB; {os.cpu_count()} cores; "
          f"outputs on {tmp_root or 'the temporary directory'}; median of {R}; "
          f"load average {res['load_start'][0]:.2f} at the start, {res['load_end'][0]:.2f} at the end")
    print()
    print("| | measured | goal |")
    print("|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]} | {r[2]} |")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(res, fh, indent=1)


if __name__ == "__main__":
    main()
