#!/usr/bin/python3
"""Writes a synthetic MRtrix3 .tck tractogram: smooth random fibres at a fixed step.

Each fibre starts inside a 80 mm ball and turns by a small random angle per
step (a persistent random walk on the sphere of directions), like
deterministic tractography at a fixed step. Used when ../shared/data is absent.
"""
import argparse
import struct

import numpy as np


def fibres(rng, step, count, max_points):
    """All fibres advance in lockstep (vectorized): returns (count, max_points, 3)."""
    d = rng.normal(size=(count, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    p = rng.uniform(-30, 30, size=(count, 3))
    curl = rng.normal(size=(count, 3)) * 0.02
    pts = np.empty((count, max_points, 3), np.float64)
    for i in range(max_points):
        pts[:, i] = p
        d = d + np.cross(curl, d) + rng.normal(size=(count, 3)) * 0.01
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        p = p + step * d
    return pts.astype("<f4")


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("output")
    ap.add_argument("--fibers", type=int, default=2000)
    ap.add_argument("--step", type=float, default=0.1)
    ap.add_argument("--min-points", type=int, default=200)
    ap.add_argument("--max-points", type=int, default=1500)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    head = (f"mrtrix tracks\ncount: {a.fibers:010d}\ndatatype: Float32LE\nstep_size: {a.step}\n"
            f"generator: fiblet make_synthetic_tck.py --seed {a.seed}\n")
    offset = len(head) + len("file: . 0000\nEND\n")
    offset = (offset + 15) // 16 * 16
    head += f"file: . {offset:04d}\nEND\n"
    with open(a.output, "wb") as f:
        f.write(head.encode().ljust(offset, b"\0"))
        sep = struct.pack("<3f", np.nan, np.nan, np.nan)
        lengths = rng.integers(a.min_points, a.max_points + 1, size=a.fibers)
        pts = fibres(rng, a.step, a.fibers, a.max_points)
        for i, n in enumerate(lengths):
            f.write(pts[i, :n].tobytes())
            f.write(sep)
        f.write(struct.pack("<3f", np.inf, np.inf, np.inf))


if __name__ == "__main__":
    main()
