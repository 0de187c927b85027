#!/usr/bin/python3
"""Size, error and encode speed of fiblet's encoder modes on the shared tractograms.

Usage: scripts/encode_table.py [--fiblet build/bin/fiblet] [--data ../shared/data] [--quick]

For every file and mode it runs `fiblet compress -j 1` (speed: points per
second of CPU time, user + system, i.e. per core), then `fiblet stats`
against the source .tck (errors as any reader decodes them). Prints a
Markdown table (docs/notes/encode-history.md, "Measured", holds one).
--quick skips efforts 3 and 4.
"""
import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile

FILES = [
    "small-ifod1.tck",
    "small-ifod1-step0.05.tck",
    "small-sdstream.tck",
    "small-ifod2.tck",
    "dwi-small64d-ifod1.tck",
    "bundles/AF_L-step0.1.tck",
    "bundles/CC_ForcepsMajor-step0.1.tck",
    "bundles/CST_R-step0.1.tck",
    "bundles/cingulum-1-step0.1.tck",
    "bundles/cingulum-2-step0.1.tck",
]

# (label, compress arguments). The default writes 8 bits; `--bits auto`
# would choose 16 for smooth fixed-step fibers (docs/encode.md, "Why smooth
# fibers need 16 bits"), and the 16-bit modes are measured on their own.
MODES = [
    ("default (8 bits)", []),
    ("8-bit effort 0", ["--bits", "8", "-e", "0"]),
    ("8-bit effort 1", ["--bits", "8"]),
    ("8-bit effort 2", ["--bits", "8", "-e", "2"]),
    ("8-bit effort 3", ["--bits", "8", "-e", "3"]),
    ("8-bit effort 4", ["--bits", "8", "-e", "4"]),
    ("8-bit zstd, effort 1", ["--bits", "8", "-z"]),
    ("8-bit zstd, effort 3", ["--bits", "8", "-z", "-e", "3"]),
    ("16-bit effort 1", ["--bits", "16"]),
    ("16-bit zstd, effort 1", ["--bits", "16", "-z"]),
]


def cpu_seconds_of(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return out, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fiblet", default=os.path.join(here, "..", "build", "bin", "fiblet"))
    ap.add_argument("--data", default=os.path.join(here, "..", "..", "shared", "data"))
    ap.add_argument("--quick", action="store_true", help="skip efforts 3 and 4")
    ap.add_argument("--files", nargs="*", default=FILES)
    a = ap.parse_args()
    modes = [m for m in MODES if not (a.quick and ("effort 3" in m[0] or "effort 4" in m[0]))]
    print("| file | mode | size | ratio vs .tck | max / mean error (µm) | encode (M points/s, 1 core) |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for f in a.files:
            src = os.path.join(a.data, f)
            if not os.path.exists(src):
                print(f"skipping missing {src}", file=sys.stderr)
                continue
            for label, args in modes:
                out = os.path.join(tmp, "x.fftz" if "-z" in args else "x.fft")
                report, cpu = cpu_seconds_of([a.fiblet, "compress", src, "-o", out, "-f", "-q", "-j", "1", "--json"] + args)
                r = json.loads(report)
                s = json.loads(subprocess.run([a.fiblet, "stats", out, "-r", src, "--json", "-q"], check=True,
                                              capture_output=True, text=True).stdout)
                e = s["error"]
                note = " (vs resampled points)" if s["resampled"] else ""
                print(f"| {f} | {label} | {s['fft_bytes'] / 1e6:.3f} MB | {s['ratio']:.2f}x | "
                      f"{e['max_um']:.2f} / {e['mean_um']:.2f}{note} | {r['points'] / cpu / 1e6:.1f} |", flush=True)


if __name__ == "__main__":
    main()
