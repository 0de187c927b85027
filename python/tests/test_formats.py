"""TrackVis .trk and TRX through fiblet, against independent references:
nibabel for .trk (MRtrix3's tckconvert reads and writes no .trk), and for TRX
a small reader/writer written here from the specification
(github.com/tee-ar-ex/trx-spec) with zipfile, json and numpy only."""
import json
import os
import struct
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest

import fiblet

nib = pytest.importorskip("nibabel")


def shared_trk(shared):
    files = sorted(shared.glob("bundles/*.trk")) + sorted(shared.glob("conformance/*.trk"))
    assert len(files) >= 9
    return files


def pytest_generate_tests(metafunc):
    if "trk" in metafunc.fixturenames:
        from conftest import SHARED
        files = sorted(SHARED.glob("bundles/*.trk")) + sorted(SHARED.glob("conformance/*.trk"))
        metafunc.parametrize("trk", files, ids=[f.name for f in files])


def nib_points(path):
    s = nib.streamlines.load(str(path)).streamlines
    return [np.asarray(f, dtype=np.float64) for f in s]


def run(cli, *args, check=True):
    r = subprocess.run([cli, *map(str, args)], capture_output=True, text=True)
    if check:
        assert r.returncode == 0, r.stderr
    return r


def point_to_polyline(p, line):
    """Exact distance from each point of p (n,3) to the polyline `line` (m,3)."""
    if len(line) == 1:
        return np.linalg.norm(p - line[0], axis=1)
    a, b = line[:-1], line[1:]
    ab = b - a
    len2 = np.maximum((ab * ab).sum(1), 1e-300)
    t = np.clip(((p[:, None, :] - a[None]) * ab[None]).sum(2) / len2[None], 0, 1)
    closest = a[None] + t[..., None] * ab[None]
    return np.linalg.norm(p[:, None, :] - closest, axis=2).min(1)


# ---- An independent TRX reader and writer (the specification's layout) ----

def trx_read(path):
    """{header, positions (N,3) float64, offsets (F+1), arrays {name: (rows, comps)}}."""
    path = Path(path)
    if path.is_dir():
        names = [str(p.relative_to(path)) for p in path.rglob("*") if p.is_file()]
        read = lambda n: (path / n).read_bytes()
    else:
        z = zipfile.ZipFile(path)
        names = [n for n in z.namelist() if not n.endswith("/")]
        read = z.read
    header = json.loads(read("header.json"))
    out = {"header": header, "arrays": {}}
    for n in names:
        if n == "header.json":
            continue
        stem, dtype = n.rsplit(".", 1)
        comps = 1
        if "." in stem.rsplit("/", 1)[-1] and stem.rsplit(".", 1)[1].isdigit():
            stem, comps = stem.rsplit(".", 1)[0], int(stem.rsplit(".", 1)[1])
        a = np.frombuffer(read(n), dtype=np.dtype(dtype).newbyteorder("<")).reshape(-1, comps)
        if stem == "positions":
            out["positions"], out["positions_dtype"] = a.astype(np.float64), a.dtype
        elif stem == "offsets":
            out["offsets"], out["offsets_dtype"] = a[:, 0].astype(np.int64), a.dtype
        else:
            out["arrays"][stem] = a
    off = out["offsets"]
    if len(off) == header["NB_STREAMLINES"]:
        off = np.append(off, header["NB_VERTICES"])
    assert off[-1] == header["NB_VERTICES"] == len(out["positions"])
    out["offsets"] = off
    return out


def trx_fibers(t):
    o = t["offsets"]
    return [t["positions"][o[i]:o[i + 1]] for i in range(len(o) - 1)]


def trx_write(path, fibers, arrays, affine=np.eye(4), dims=(1, 1, 1), positions="float16",
              offsets="uint32", sentinel=False, deflate=True):
    lengths = [len(f) for f in fibers]
    off = np.concatenate([[0], np.cumsum(lengths)]).astype(offsets)
    if not sentinel:
        off = off[:-1]
    files = {
        "header.json": json.dumps({"VOXEL_TO_RASMM": np.asarray(affine).tolist(), "DIMENSIONS": list(dims),
                                   "NB_STREAMLINES": len(fibers), "NB_VERTICES": int(sum(lengths))}).encode(),
        f"positions.3.{positions}": np.concatenate(fibers).astype("<" + np.dtype(positions).str[1:]).tobytes(),
        f"offsets.{offsets}": off.astype("<" + np.dtype(offsets).str[1:]).tobytes(),
    }
    for name, a in arrays.items():
        a = np.asarray(a)
        comps = "" if a.ndim == 1 or a.shape[1] == 1 else f".{a.shape[1]}"
        files[f"{name}{comps}.{a.dtype.name}"] = a.astype(a.dtype.newbyteorder("<")).tobytes()
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED if deflate else zipfile.ZIP_STORED) as z:
        for n, b in files.items():
            z.writestr(n, b)


# ---- .trk: fiblet's reader gives nibabel's coordinates and data ----

def test_trk_reader_gives_nibabels_streamlines(trk):
    s, data = fiblet.read_streamlines(trk)
    t = nib.streamlines.load(str(trk))
    ref = t.streamlines
    assert len(s) == len(ref)
    for a, b in zip(s, ref):
        # nibabel applies the float32 affine in float32: at most a rounding apart
        np.testing.assert_allclose(a, b, rtol=0, atol=4 * np.finfo(np.float32).eps * max(1, np.abs(b).max()))
    for k, v in t.tractogram.data_per_point.items():
        np.testing.assert_array_equal(data[f"dpv/{k}"], np.concatenate(list(v)))
    for k, v in t.tractogram.data_per_streamline.items():
        np.testing.assert_array_equal(data[f"dps/{k}"], v)
    assert len(data) == len(t.tractogram.data_per_point) + len(t.tractogram.data_per_streamline)


# ---- .trk -> .fft -> .trk / .trx, read back by nibabel and the TRX oracle ----

@pytest.fixture(scope="module")
def round_trips(tmp_path_factory, cli):
    out = tmp_path_factory.mktemp("trk")
    cache = {}

    def make(trk):
        if trk not in cache:
            fft = out / (trk.stem + ".fft")
            report = json.loads(run(cli, "compress", "--json", "-q", trk, "-o", fft).stdout)
            run(cli, "decompress", "-q", fft, "-o", out / (trk.stem + ".trk"))
            run(cli, "decompress", "-q", fft, "-o", out / (trk.stem + ".trx"))
            info = fiblet.info(fft)
            cache[trk] = (out / (trk.stem + ".trk"), out / (trk.stem + ".trx"), report, info)
        return cache[trk]
    return make


def check_decoded(original, decoded, info, report, slack=0.0):
    """Fixed-step input: every decoded point within the error the .fft
    records of its input point. Resampled input (points on the cubic through
    the input's points): every decoded point as close to the input polyline
    as fiblet's own measure of it says (compress --json, decoded -> input),
    read here through nibabel or the TRX oracle instead of fiblet. `slack`:
    what the output's dtype adds (half a float16 step)."""
    resampled = report["resampled"]
    recorded = report["geometry"]["decoded_to_input"]["max_um"] if resampled else info["max_error_um"]
    bound = recorded * 1e-3 * (1 + 1e-3) + 1e-4 + slack  # + float32 voxmm rounding of a .trk
    assert len(decoded) == len(original)
    worst = 0.0
    for a, b in zip(original, decoded):
        if resampled:
            d = point_to_polyline(np.asarray(b, np.float64), a) if len(b) else np.zeros(0)
        else:
            assert len(a) == len(b)
            d = np.linalg.norm(np.asarray(b, np.float64) - a, axis=1)
        worst = max(worst, d.max(initial=0))
    assert worst <= bound, (worst, bound)
    return worst


def test_trk_round_trip_read_by_nibabel(trk, round_trips):
    out_trk, _, report, info = round_trips(trk)
    original = nib_points(trk)
    t = nib.streamlines.load(str(out_trk))
    check_decoded(original, list(t.streamlines), info, report)
    # The header's space comes back.
    src = nib.streamlines.load(str(trk), lazy_load=True).header
    got = t.header
    for key in ("voxel_to_rasmm", "dimensions", "voxel_sizes"):
        np.testing.assert_array_equal(got[key], src[key])
    assert got["voxel_order"] == src["voxel_order"]
    # Data per streamline unchanged; per point unchanged unless resampled.
    ref = nib.streamlines.load(str(trk)).tractogram
    for k, v in ref.data_per_streamline.items():
        np.testing.assert_array_equal(t.tractogram.data_per_streamline[k], v)
    if not report["resampled"]:
        for k, v in ref.data_per_point.items():
            np.testing.assert_array_equal(np.concatenate(list(t.tractogram.data_per_point[k])),
                                          np.concatenate(list(v)))


def test_trk_round_trip_to_trx_read_by_spec_reader(trk, round_trips):
    _, out_trx, report, info = round_trips(trk)
    t = trx_read(out_trx)
    assert t["header"]["NB_STREAMLINES"] == len(t["offsets"]) - 1
    src = nib.streamlines.load(str(trk), lazy_load=True).header
    np.testing.assert_array_equal(np.asarray(t["header"]["VOXEL_TO_RASMM"]), src["voxel_to_rasmm"])
    np.testing.assert_array_equal(t["header"]["DIMENSIONS"], src["dimensions"])
    check_decoded(nib_points(trk), trx_fibers(t), info, report)
    ref = nib.streamlines.load(str(trk)).tractogram
    for k, v in ref.data_per_streamline.items():
        np.testing.assert_array_equal(t["arrays"][f"dps/{k}"], v)


def test_python_save_of_trk_goes_through_the_same_reader(tmp_path, shared, cli):
    src = shared / "conformance/complex.trk"
    report = fiblet.save(tmp_path / "py.fft", src)
    run(cli, "compress", "-q", src, "-o", tmp_path / "cli.fft")
    assert report["fibers"] == 3
    assert (tmp_path / "py.fft").read_bytes() == (tmp_path / "cli.fft").read_bytes()
    s, data = fiblet.read_streamlines(src)
    assert len(data) == 5 and len(s) == 3


def cubic_offset_bound(f):
    """How far a point of the cubic through f's points (formats/fft.md §5)
    can be from the chord point of the same parameter: on segment i,
    d_i (4/27) (|m_i - u_i| + |m_i+1 - u_i|), and each Bessel tangent m
    (a convex combination of the two unit chords at its point) is within
    the turn angle there of either chord; the fiber's fitted tension
    (at most 4) scales m: |tension m - u| <= 4 |m - u| + 3."""
    d = np.linalg.norm(np.diff(f.astype(np.float64), axis=0), axis=1)
    u = np.diff(f.astype(np.float64), axis=0) / d[:, None]
    turn = np.arccos(np.clip((u[1:] * u[:-1]).sum(1), -1, 1))
    turn_at = np.concatenate([[turn[0]], turn, [turn[-1]]])  # per point: its turn (the ends: their neighbour's)
    return float((d * 4 / 27 * (4 * (turn_at[:-1] + turn_at[1:]) + 6)).max())


def test_resampled_point_data_follows_the_polyline(tmp_path, cli):
    """Variable spacing is resampled; a per-point value equal to x + 2y is
    interpolated linearly between the two input points of the piece each new
    point lies on, so at every decoded point it stays within the point error
    plus the cubic's offset from its chord of the decoded x + 2y."""
    rng = np.random.default_rng(7)
    fibers, values = [], []
    for _ in range(40):
        steps = rng.uniform(0.2, 1.4, size=(60, 1)) * np.array([[1.0, 0.3, 0.1]]) + rng.normal(0, 0.05, (60, 3))
        f = (np.cumsum(steps, axis=0) + rng.uniform(-20, 20, 3)).astype(np.float32)
        fibers.append(f)
        values.append((f[:, 0] + 2 * f[:, 1]).astype(np.float32)[:, None])
    tg = nib.streamlines.Tractogram(fibers, affine_to_rasmm=np.eye(4))
    tg.data_per_point["lin"] = values
    tg.data_per_streamline["id"] = np.arange(40, dtype=np.float32)[:, None]
    nib.streamlines.save(tg, str(tmp_path / "var.trk"))
    report = json.loads(run(cli, "compress", "--json", "-q", tmp_path / "var.trk", "-o", tmp_path / "v.fft").stdout)
    assert report["resampled"]
    run(cli, "decompress", "-q", tmp_path / "v.fft", "-o", tmp_path / "v.trk")
    back = nib.streamlines.load(str(tmp_path / "v.trk")).tractogram
    for f_in, f, v in zip(fibers, back.streamlines, back.data_per_point["lin"]):
        bound = (report["max_error_um"] * 1e-3 + cubic_offset_bound(f_in)) * 3 + 1e-3  # |dx + 2 dy| <= 3 |d|
        np.testing.assert_allclose(v[:, 0], f[:, 0] + 2 * f[:, 1], rtol=0, atol=bound)
    np.testing.assert_array_equal(back.data_per_streamline["id"][:, 0], np.arange(40))


# ---- TRX from the independent writer: dtypes, groups, no sentinel ----

@pytest.mark.parametrize("positions,offsets,sentinel,deflate", [
    ("float16", "uint32", False, True), ("float32", "uint64", True, False), ("float64", "uint64", False, True)])
def test_trx_written_by_spec_writer_round_trips(tmp_path, cli, positions, offsets, sentinel, deflate):
    rng = np.random.default_rng(3)
    fibers = [np.cumsum(rng.normal(0, 0.5, (n, 3)), axis=0) + 10 for n in (30, 45, 1, 60)]
    fibers = [f.astype(positions).astype(np.float64) for f in fibers]  # what the file holds
    arrays = {"dps/weight": np.array([0.5, 1.5, 2.5, 3.5], np.float32),
              "dps/label": np.array([[1, 2], [3, 4], [5, 6], [7, 8]], np.int16),
              "dpv/fa": np.linspace(0, 1, 136).astype(np.float16),
              "groups/CST": np.array([3, 1], np.uint32),
              "dpg/CST/volume": np.array([42], np.uint32)}
    affine = np.array([[-1.5, 0, 0, 90], [0, 1.5, 0, -126], [0, 0, 1.5, -72], [0, 0, 0, 1]])
    trx_write(tmp_path / "in.trx", fibers, arrays, affine, (121, 145, 121), positions, offsets, sentinel, deflate)
    s, data = fiblet.read_streamlines(tmp_path / "in.trx")
    for a, b in zip(s, fibers):
        np.testing.assert_array_equal(a, b.astype(np.float32))
    report = json.loads(run(cli, "compress", "--json", "-q", "--step", "0.5", tmp_path / "in.trx",
                            "-o", tmp_path / "x.fft").stdout)
    run(cli, "decompress", "-q", tmp_path / "x.fft", "-o", tmp_path / "out.trx")
    t = trx_read(tmp_path / "out.trx")
    np.testing.assert_array_equal(t["header"]["VOXEL_TO_RASMM"], affine)
    assert t["header"]["DIMENSIONS"] == [121, 145, 121]
    decoded = trx_fibers(t)
    # Positions and offsets come back in the source's dtypes (formats/fft-data.md):
    # float16 ones are the decoded points rounded to float16 (half a step of at most 2^-5 mm below 64 mm).
    assert t["positions_dtype"] == np.dtype(positions) and t["offsets_dtype"] == np.dtype(offsets)
    assert np.abs(t["positions"]).max() < 64
    slack = 2.0 ** -6 * np.sqrt(3) if positions == "float16" else 0.0
    check_decoded(fibers, decoded, fiblet.info(tmp_path / "x.fft"), report, slack)
    for name in ("dps/weight", "dps/label", "groups/CST", "dpg/CST/volume"):
        np.testing.assert_array_equal(t["arrays"][name].reshape(arrays[name].shape), arrays[name])
        assert t["arrays"][name].dtype == arrays[name].dtype, name
    assert t["arrays"]["dpv/fa"].shape == (len(t["positions"]), 1)  # resampled with the points
    assert t["arrays"]["dpv/fa"].dtype == np.float16  # interpolated, back in its dtype
    # A .trk cannot hold groups: a clear error, exit 6, no output.
    r = run(cli, "decompress", tmp_path / "x.fft", "-o", tmp_path / "out.trk", check=False)
    assert r.returncode == 6 and "groups" in r.stderr and not (tmp_path / "out.trk").exists()


# ---- Recognised formats, malformed files, exit codes ----

def le32(v):
    return struct.pack("<i", v)


def patched(src, tmp_path, name, offset, data=None):
    b = bytearray(Path(src).read_bytes())
    if data is None:
        del b[offset:]
    else:
        b[offset:offset + len(data)] = data
    p = tmp_path / name
    p.write_bytes(bytes(b))
    return p


def test_malformed_trk_exit_4_unsupported_exit_6(tmp_path, shared, cli):
    src = shared / "conformance/simple.trk"
    cases = {
        "truncated_header.trk": (500, None, 4, "truncated header"),
        "truncated_data.trk": (1050, None, 4, "truncated"),
        "hdr_size.trk": (996, le32(1234), 4, "hdr_size"),
        "n_count.trk": (988, le32(7), 4, "n_count"),
        "version.trk": (992, le32(9), 6, "version 9"),
    }
    for name, (offset, data, code, words) in cases.items():
        p = patched(src, tmp_path, name, offset, data)
        r = run(cli, "compress", p, "-o", tmp_path / (name + ".fft"), check=False)
        assert r.returncode == code, (name, r.stderr)
        assert words in r.stderr and str(p) in r.stderr, r.stderr
        assert not (tmp_path / (name + ".fft")).exists()


def test_malformed_trx_exit_4(tmp_path, cli):
    fibers = [np.zeros((3, 3)), np.ones((2, 3))]
    trx_write(tmp_path / "ok.trx", fibers, {}, positions="float32", offsets="uint64", sentinel=True)
    z = zipfile.ZipFile(tmp_path / "ok.trx")
    entries = {n: z.read(n) for n in z.namelist()}

    def variant(name, **changes):
        with zipfile.ZipFile(tmp_path / name, "w") as out:
            for n, b in {**entries, **changes}.items():
                if b is not None:
                    out.writestr(n, b)
        return tmp_path / name
    bad = {
        "offsets.trx": {"offsets.uint64": np.array([0, 4, 5], "<u8").tobytes()[:-8] + np.array([9], "<u8").tobytes()},
        "decreasing.trx": {"offsets.uint64": np.array([0, 4, 2], "<u8").tobytes()},
        "positions.trx": {"positions.3.float32": entries["positions.3.float32"][:-12]},
        "header.trx": {"header.json": b"{not json"},
        "nohead.trx": {"header.json": None},
    }
    for name, change in bad.items():
        p = variant(name, **change)
        r = run(cli, "compress", p, "-o", tmp_path / (name + ".fft"), check=False)
        assert r.returncode == 4, (name, r.stderr)
        assert "not a valid TRX file" in r.stderr, r.stderr
    (tmp_path / "cut.trx").write_bytes((tmp_path / "ok.trx").read_bytes()[:40])
    r = run(cli, "compress", tmp_path / "cut.trx", "-o", tmp_path / "cut.fft", check=False)
    assert r.returncode == 4 and "zip" in r.stderr, r.stderr


def test_formats_are_named(tmp_path, shared, cli):
    # A .trk given to info reads as a .trk; a .tck given to load is named.
    r = run(cli, "info", shared / "conformance/standard.LPS.trk")
    assert "TrackVis .trk" in r.stdout and "LPS" in r.stdout
    j = json.loads(run(cli, "info", "--json", shared / "conformance/complex_big_endian.trk").stdout)
    ref = nib.streamlines.load(str(shared / "conformance/complex_big_endian.trk"))
    assert j["format"] == "trk" and j["streamlines"] == len(ref.streamlines)
    assert j["points"] == len(ref.streamlines.get_data())
    assert sorted(j["data"]) == sorted([f"dpv/{k}" for k in ref.tractogram.data_per_point] +
                                       [f"dps/{k}" for k in ref.tractogram.data_per_streamline])
    with pytest.raises(fiblet.FibletError, match="MRtrix3 .tck tractogram, not a .fft") as e:
        fiblet.load(shared / "conformance/simple.tck")
    assert e.value.category == "unsupported"
    (tmp_path / "x.vtk").write_text("# vtk DataFile Version 3.0\nx\nASCII\n")
    r = run(cli, "compress", tmp_path / "x.vtk", "-o", tmp_path / "x.fft", check=False)
    assert r.returncode == 6 and "VTK" in r.stderr
    r = run(cli, "decompress", "-q", "--force", "-o", tmp_path / "x.vtk",
            run(cli, "compress", "-q", shared / "conformance/simple.trk", "-o", tmp_path / "s.fft") and tmp_path / "s.fft",
            check=False)
    assert r.returncode == 6 and ".trk and .trx" in r.stderr
    with zipfile.ZipFile(tmp_path / "notes.zip", "w") as z:
        z.writestr("a.txt", "not a tractogram")
    r = run(cli, "compress", tmp_path / "notes.zip", "-o", tmp_path / "n.fft", check=False)
    assert r.returncode == 6 and "without TRX's header.json" in r.stderr, r.stderr
    (tmp_path / "junk.bin").write_bytes(b"\x07" * 100)
    r = run(cli, "compress", tmp_path / "junk.bin", "-o", tmp_path / "j.fft", check=False)
    assert r.returncode == 4 and "not a tractogram" in r.stderr
