#!/usr/bin/python3
"""The compress speed guard: instructions (callgrind) against a committed budget.

Counts the instructions `fiblet compress` executes, one thread, at the default
effort and at --effort 0, on the first fibers of a shared tractogram, and fails
when either rises more than 25 % above bench/instruction_budget.json, or when
the default's share over --effort 0 rises more than 25 %. Instruction counts do
not depend on the machine's load; valgrind runs the AVX2 paths whatever the CPU
(it has no AVX-512), so the budget holds on every x86-64 machine this project
runs on. After a change that is meant to cost more (or less), rerun with
--update and commit the new budget with the change's measurements.

  bench/instruction_budget.py --fiblet build/bin/fiblet --tck ../shared/data/small-ifod1.tck [--update]
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

TOLERANCE = 1.25
FIBERS = 600
BUDGET = os.path.join(os.path.dirname(os.path.abspath(__file__)), "instruction_budget.json")
RUNS = {"default": [], "effort 0": ["--effort", "0"]}


def first_fibers(tck, count, out):
    """The header of `tck` and its first `count` streamlines (float32 .tck), as a new .tck."""
    with open(tck, "rb") as f:
        data = f.read()
    head_end = data.index(b"\nEND\n") + 5
    offset = int(re.search(rb"\nfile:\s*\.\s+(\d+)", data[:head_end]).group(1))
    import numpy as np

    pts = np.frombuffer(data, dtype="<f4", offset=offset).reshape(-1, 3)
    ends = np.flatnonzero(np.isnan(pts[:, 0]))
    cut = ends[count - 1] + 1 if len(ends) >= count else len(pts) - 1
    header = re.sub(rb"\ncount:\s*\d+", b"\ncount: %d" % min(count, len(ends)), data[:head_end])
    with open(out, "wb") as f:
        f.write(header.ljust(offset, b"\0") if len(header) <= offset else header)
        f.write(pts[:cut].tobytes())
        f.write(np.array([np.inf] * 3, dtype="<f4").tobytes())


def instructions(fiblet, tck, extra, work):
    out = os.path.join(work, "out.fft")
    cmd = ["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", fiblet, "compress", "-q", "-f", "-j", "1",
           *extra, tck, "-o", out]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"instruction_budget: {' '.join(cmd)} failed:\n{r.stderr[-2000:]}")
    m = re.search(r"Collected\s*:\s*(\d+)", r.stderr) or re.search(r"I\s+refs:\s*([\d,]+)", r.stderr)
    return int(m.group(1).replace(",", ""))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--fiblet", required=True)
    p.add_argument("--tck", required=True)
    p.add_argument("--update", action="store_true", help="write the measured counts as the new budget")
    p.add_argument("--sanitized", action="store_true",
                   help="the binary is an AddressSanitizer build: skip (exit 77), valgrind cannot run it")
    args = p.parse_args()
    if args.sanitized:
        print("skipped: an AddressSanitizer build (valgrind cannot run it, and its counts are not compress's)")
        sys.exit(77)
    with tempfile.TemporaryDirectory(prefix="fiblet-budget-") as work:
        tck = os.path.join(work, "in.tck")
        first_fibers(args.tck, FIBERS, tck)
        counts = {name: instructions(args.fiblet, tck, extra, work) for name, extra in RUNS.items()}
    counts["default / effort 0"] = counts["default"] / counts["effort 0"]
    for name, n in counts.items():
        print(f"{name}: {n:,.0f}" if n > 100 else f"{name}: {n:.3f}")
    if args.update:
        with open(BUDGET, "w") as f:
            json.dump({"input": f"first {FIBERS} fibers of {os.path.basename(args.tck)}", **counts}, f, indent=1)
            f.write("\n")
        return
    with open(BUDGET) as f:
        budget = json.load(f)
    failed = [f"{name}: {counts[name]:,.3f} > {TOLERANCE} x the budget {budget[name]:,.3f}"
              for name in counts if counts[name] > TOLERANCE * budget[name]]
    for line in failed:
        print("over budget:", line)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
