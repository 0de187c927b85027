#!/usr/bin/env python3
"""Round trips of every shared .trk through fiblet, measured with nibabel:
.trk -> fiblet compress -> .fft -> fiblet decompress -> .trk and .trx.
Prints a markdown table: sizes, and the largest distance from a decoded
point (read back by nibabel, or for .trx by zipfile + numpy) to its source
streamline as nibabel loads it (to the polyline when the input was resampled).

usage: scripts/trk_table.py FIBLET_CLI SHARED_DATA_DIR WORK_DIR
"""
import json
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import nibabel as nib


def to_polyline(p, line):
    if len(line) == 1:
        return np.linalg.norm(p - line[0], axis=1)
    a, b = line[:-1], line[1:]
    ab = b - a
    t = np.clip(((p[:, None] - a[None]) * ab[None]).sum(2) / np.maximum((ab * ab).sum(1), 1e-300)[None], 0, 1)
    return np.linalg.norm(p[:, None] - (a[None] + t[..., None] * ab[None]), axis=2).min(1)


def worst(orig, dec):
    assert len(orig) == len(dec)
    return max((to_polyline(np.asarray(b, float), np.asarray(a, float)).max() for a, b in zip(orig, dec) if len(b)),
               default=0.0)


def trx_fibers(path):
    z = zipfile.ZipFile(path)
    pos = np.frombuffer(z.read("positions.3.float32"), "<f4").reshape(-1, 3)
    off = np.frombuffer(z.read("offsets.uint64"), "<u8")
    return [pos[off[i]:off[i + 1]] for i in range(len(off) - 1)]


def main(cli, shared, work):
    work = Path(work)
    work.mkdir(parents=True, exist_ok=True)
    print("| file | streamlines | .trk bytes | .fft bytes | ratio | resampled | max error .trk (µm) | max error .trx (µm) |")
    print("|---|---|---|---|---|---|---|---|")
    for trk in sorted(Path(shared).glob("bundles/*.trk")) + sorted(Path(shared).glob("conformance/*.trk")):
        fft, out_trk, out_trx = (work / (trk.stem + e) for e in (".fft", ".trk", ".trx"))
        r = json.loads(subprocess.run([cli, "compress", "-f", "-q", "--json", str(trk), "-o", str(fft)],
                                      check=True, capture_output=True, text=True).stdout)
        for out in (out_trk, out_trx):
            subprocess.run([cli, "decompress", "-f", "-q", str(fft), "-o", str(out)], check=True)
        orig = list(nib.streamlines.load(str(trk)).streamlines)
        e_trk = worst(orig, list(nib.streamlines.load(str(out_trk)).streamlines)) * 1e3
        e_trx = worst(orig, trx_fibers(out_trx)) * 1e3
        print(f"| {trk.parent.name}/{trk.name} | {len(orig)} | {trk.stat().st_size} | {fft.stat().st_size} | "
              f"{trk.stat().st_size / fft.stat().st_size:.2f} | {'yes' if r['resampled'] else 'no'} | "
              f"{e_trk:.2f} | {e_trx:.2f} |")


if __name__ == "__main__":
    main(*sys.argv[1:4])
