#!/usr/bin/env python3
"""Makes the conformance corpus tests/conformance/: small .fft/.fftz files
of every version and chunk, with edge cases (1/2/3-point fibers, block
boundaries 59/60/61, 119/120/121 and 253/254/255 points, first axes along
+C and -C of the direction frame, resampled input with its RSMP and ENDS
chunks, an empty tractogram), each with the points fiblet decodes from it
(float32, as `fiblet decompress` writes them) as text: what any reader of
the format can check itself against, and what the suite checks the
decoders against (tests/conformance_test.cpp).

    scripts/make_conformance.py [--fiblet build/bin/fiblet]

Run it again only to add cases: the files are fixed once committed (older
files must keep decoding to the same points)."""
import argparse
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
OUT = ROOT / "tests" / "conformance"
C = np.array([-0.703023156622, 0.039959276793, 0.71004344758])  # formats/fft.md §4


def write_tck(path, fibers):
    header = "mrtrix tracks\ndatatype: Float32LE\ncount: {:010d}\nfile: . {{}}\nEND\n".format(len(fibers))
    offset = len(header.format(0)) + 8
    header = header.format(offset).ljust(offset, " ")
    body = bytearray()
    for f in fibers:
        body += np.asarray(f, dtype="<f4").tobytes() + np.full(3, np.nan, "<f4").tobytes()
    body += np.full(3, np.inf, "<f4").tobytes()
    path.write_bytes(header.encode() + bytes(body))


def smooth(n, step, seed):
    """A wiggly fiber of n points `step` mm apart (fixed step)."""
    rng = np.random.default_rng(seed)
    d = np.array([1.0, 0.2, 0.1])
    p = np.zeros(3)
    pts = []
    for _ in range(n):
        pts.append(p.copy())
        d = d + rng.normal(0, 0.08, 3)
        d /= np.linalg.norm(d)
        p = p + step * d
    return np.array(pts) + np.array([float(seed), 0, 0])


def cases():
    lengths = [1, 2, 3, 59, 60, 61, 119, 120, 121, 253, 254, 255]
    yield "lengths", "fibers of 1, 2, 3, 59-61, 119-121 and 253-255 points at a 0.5 mm step (block boundaries of 60 and 254 points)", \
        [smooth(n, 0.5, i) for i, n in enumerate(lengths)]
    for step in (2.0, 0.1):
        along = [10 * C + np.arange(40)[:, None] * step * sign * C for sign in (1, -1)]  # every step along +-C
        turn = np.arange(1, 20)[:, None] * step * np.array([1.0, 0, 0])
        along.append(np.vstack([np.arange(20)[:, None] * step * C, 19 * step * C + turn]))  # first axis C, then a turn
        yield f"along-c-{step:g}mm", (f"straight fibers along +C and -C of the frame helper and one whose first axis is C "
                                      f"then turns, at a fixed {step:g} mm step: the C' fallback"), along
    rng = np.random.default_rng(7)
    sparse = []
    for i in range(5):
        pts = smooth(30, 0.5, 40 + i)
        keep = np.sort(rng.choice(np.arange(1, 29), 12, replace=False))
        sparse.append(pts[np.concatenate([[0], keep, [29]])])
    yield "resampled", "unevenly spaced fibers: resampled to a fixed step (RSMP chunk) with their true ends (ENDS chunk)", sparse
    yield "empty", "a tractogram with no streamline", []


VARIANTS = [
    ("v2.fft", [], "version 2 (8-bit directions, 60-point blocks), the official layout"),
    ("v17.fft", ["--bits", "16"], "version 17 (16-bit directions, packed 254-point blocks)"),
    ("v16.fftz", ["--bits", "16", "--zstd"], "version 16 in the seekable zstd container"),
    ("v2.fftz", ["--zstd"], "version 2 in the seekable zstd container"),
]


def points_text(tck):
    """fiblet's decode, read back from its .tck: 'fiber N: M points' then x y z per line (%.9g: float32 exact)."""
    data = np.fromfile(tck, dtype="<f4", offset=int(next(l for l in open(tck, "rb").read(4096).decode("latin1").splitlines() if l.startswith("file:")).split()[2]))
    pts = data.reshape(-1, 3)
    lines, fiber, current = [], 0, []
    for p in pts:
        if np.isinf(p).all():
            break
        if np.isnan(p).all():
            lines.append(f"fiber {fiber}: {len(current)} points")
            lines += current
            fiber, current = fiber + 1, []
        else:
            current.append(" ".join(f"{float(v):.9g}" for v in p))
    return "\n".join(lines) + ("\n" if lines else "")


def write_float64(exact_points, path):
    """NAME.f64.txt: the float64 reference decode (a .fftz through the spec's unpacking, tests/fftz_spec_reader.hpp)."""
    exact = subprocess.run([exact_points, str(path)], check=True, capture_output=True, text=True)
    pathlib.Path(str(path) + ".f64.txt").write_text(exact.stdout)


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("--fiblet", default=str(ROOT / "build" / "bin" / "fiblet"))
    a.add_argument("--exact-points", default=str(ROOT / "build" / "tests" / "fiblet_exact_points"),
                   help="the float64 reference decoder's text output (tests/tools/exact_points.cpp)")
    a.add_argument("--add-float64", action="store_true",
                   help="only write the NAME.f64.txt files missing beside the committed corpus files (no file is remade)")
    args = a.parse_args()
    if args.add_float64:
        for path in sorted(OUT.glob("*.fft*")):
            if path.suffix in (".fft", ".fftz") and not pathlib.Path(str(path) + ".f64.txt").exists():
                write_float64(args.exact_points, path)
        return 0
    OUT.mkdir(parents=True, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, what, fibers in cases():
            tck = pathlib.Path(tmp) / f"{name}.tck"
            write_tck(tck, fibers)
            for suffix, options, version in VARIANTS:
                out = OUT / f"{name}-{suffix}"
                subprocess.run([args.fiblet, "compress", "-q", "-f", str(tck), "-o", str(out), *options], check=True)
                decoded = pathlib.Path(tmp) / "decoded.tck"
                subprocess.run([args.fiblet, "decompress", "-q", "-f", str(out), "-o", str(decoded)], check=True)
                (OUT / f"{name}-{suffix}.txt").write_text(points_text(decoded))
                write_float64(args.exact_points, out)
                rows.append(f"| `{name}-{suffix}` | {version} | {what} |")
    (OUT / "README.md").write_text(
        "# Conformance corpus\n\nSmall files of every `.fft` version and chunk, each with the points fiblet decodes "
        "from it (`NAME.txt`: `fiber N: M points`, then `x y z` per point in world mm, float32 values printed "
        "exactly with 9 significant digits) and the float64 reference decode "
        "(`NAME.f64.txt`, the same form, 17 significant digits: `tests/exact_decoder.hpp`, written from `formats/` "
        "alone, every formula in double; a `.fftz` unpacked as `formats/fftz.md` says by `tests/fftz_spec_reader.hpp`), for any reader of `formats/` to check itself against; the suite "
        "decodes each with every decoder (`tests/conformance_test.cpp`: bit for bit for scalar and lanes, within 0.5 µm for the warp decoders' prefix products, every decoder within 0.5 µm of the float64 points, which the reference decoder reproduces exactly). Made once by `scripts/make_conformance.py`; "
        "never regenerated (older files must keep decoding to the same points; `--add-float64` writes a missing `NAME.f64.txt` only).\n\n"
        "| file | version | what it exercises |\n|---|---|---|\n" + "\n".join(rows) + "\n")


if __name__ == "__main__":
    sys.exit(main())
