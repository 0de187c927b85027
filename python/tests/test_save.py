"""fiblet.save: streamlines from Python objects into .fft, read back and
measured against the points given; the format chosen by the output's
extension (.fft, .fftz, .tck, .trk, .trx), each read back by another reader
(nibabel, the TRX layout read with zipfile and numpy), any other refused."""
import json
import struct
import subprocess
import zipfile

import numpy as np
import pytest

import fiblet

nib = pytest.importorskip("nibabel")


def max_distance(streamlines, fibers):
    assert len(streamlines) == len(fibers)
    worst = 0.0
    for mine, theirs in zip(streamlines, fibers):
        assert mine.shape == np.shape(theirs)
        worst = max(worst, float(np.linalg.norm(mine - np.asarray(theirs, np.float64), axis=1).max()))
    return worst


def test_save_array_sequence_round_trip(tmp_path, shared):
    seq = nib.streamlines.load(str(shared / "dwi-small64d-ifod1.tck")).streamlines
    out = tmp_path / "af.fft"
    report = fiblet.save(out, seq)
    assert report["fibers"] == len(seq) and report["points"] == len(seq.get_data())
    assert report["output"] == str(out) and report["ratio"] > 1
    back = fiblet.load(out)
    worst = max_distance(back, seq)
    # Within the error the encoder reports and the header records.
    assert worst <= report["max_error_um"] * 1e-3 * (1 + 1e-4) + 1e-7
    assert worst <= fiblet.info(out)["max_error_um"] * 1e-3 * (1 + 1e-4) + 1e-7


def test_save_list_tractogram_and_streamlines(tmp_path, shared):
    seq = nib.streamlines.load(str(shared / "dwi-small64d-ifod1.tck")).streamlines
    fibers = [np.array(f, dtype=np.float64) for f in seq]  # plain list, other dtype
    fiblet.save(tmp_path / "list.fft", fibers)
    a = fiblet.load(tmp_path / "list.fft")
    assert max_distance(a, fibers) < 0.05

    # A Tractogram whose points are in voxels: save() writes world mm.
    affine = np.diag([2.0, 2.0, 2.0, 1.0])
    affine[:3, 3] = [10, -5, 3]
    voxels = [(f - affine[:3, 3]) / 2.0 for f in fibers]
    t = nib.streamlines.Tractogram(voxels, affine_to_rasmm=affine)
    fiblet.save(tmp_path / "tractogram.fft", t)
    assert max_distance(fiblet.load(tmp_path / "tractogram.fft"), fibers) < 0.05

    # A fiblet.Streamlines of the same points (decoded points would not do:
    # their spacing varies by the codec's error, so they would be resampled).
    offsets = np.concatenate([[0], np.cumsum([len(f) for f in fibers])])
    s = fiblet.Streamlines(np.concatenate(fibers).astype(np.float32), offsets)
    fiblet.save(tmp_path / "streamlines.fft", s)
    np.testing.assert_array_equal(fiblet.load(tmp_path / "streamlines.fft").points, a.points)


def test_save_with_step_resamples_variable_spacing(tmp_path, shared):
    # AF_L.tck has 6 mm steps of varying length: compressed at a fixed 0.5 mm.
    seq = nib.streamlines.load(str(shared / "bundles" / "AF_L.tck")).streamlines
    report = fiblet.save(tmp_path / "af.fft", seq, step=0.5)
    assert report["resampled"] and abs(report["step_mm"] - 0.5) < 1e-6
    back = fiblet.load(tmp_path / "af.fft")
    assert len(back) == len(seq)
    # Resampled fibers: more points, same end points within the error.
    for mine, theirs in zip(back, seq):
        assert len(mine) > len(theirs)
        assert np.linalg.norm(mine[0] - theirs[0]) < 0.05


def test_save_refuses_bad_input_and_existing_output(tmp_path):
    fibers = [np.array([[0, 0, 0], [0.1, 0, 0], [0.2, 0, 0]], np.float32)]
    out = tmp_path / "x.fft"
    fiblet.save(out, fibers)
    with pytest.raises(FileExistsError):
        fiblet.save(out, fibers)
    fiblet.save(out, fibers, overwrite=True)
    bad = [np.array([[0, 0, 0], [np.nan, 0, 0]], np.float32)]
    with pytest.raises(ValueError):
        fiblet.save(tmp_path / "nan.fft", bad)
    assert not (tmp_path / "nan.fft").exists()
    with pytest.raises(ValueError):
        fiblet.save(tmp_path / "shape.fft", (np.zeros((4, 2), np.float32), np.array([0, 4])))
    with pytest.raises(ValueError):  # (3, 2) must not be taken for (2, 3)
        fiblet.save(tmp_path / "shape.fft", [np.zeros((3, 2), np.float32)])
    with pytest.raises(fiblet.FibletError):  # offsets that do not fit the points
        fiblet.save(tmp_path / "offsets.fft", (np.zeros((4, 3), np.float32), np.array([0, 5])))
    assert not any(tmp_path.glob("shape.fft*")) and not any(tmp_path.glob("offsets.fft*"))


def test_save_report_has_the_cli_json_keys(tmp_path, shared, cli):
    tck = shared / "dwi-small64d-ifod1.tck"
    cli_report = json.loads(subprocess.run([cli, "compress", "--json", "-q", str(tck), "-o", str(tmp_path / "c.fft")],
                                           check=True, capture_output=True, text=True).stdout)
    py_report = fiblet.save(tmp_path / "p.fft", nib.streamlines.load(str(tck)).streamlines)
    assert set(py_report) == set(cli_report)
    for key in ("fibers", "points", "blocks", "max_error_um", "mean_error_um", "step_mm"):
        assert py_report[key] == pytest.approx(cli_report[key], rel=1e-6), key


# ---- The output's extension chooses the format ----

@pytest.fixture(scope="module")
def dwi_seq(shared):
    return nib.streamlines.load(str(shared / "dwi-small64d-ifod1.tck")).streamlines


def assert_same_fibers(points, lengths, seq, atol=0.0):
    np.testing.assert_array_equal(lengths, seq._lengths)
    if atol:
        np.testing.assert_allclose(points, seq.get_data(), rtol=0, atol=atol)
    else:
        np.testing.assert_array_equal(points, seq.get_data())


@pytest.mark.parametrize("name, magic", [("out.tck", b"mrtrix tracks\n"), ("out.trk", b"TRACK"),
                                         ("OUT.TCK", b"mrtrix tracks\n")])
def test_save_tck_and_trk_are_what_nibabel_reads(tmp_path, dwi_seq, name, magic):
    out = tmp_path / name
    report = fiblet.save(out, dwi_seq)
    # The bytes of the format named, not a .fft under that name.
    assert out.read_bytes().startswith(magic)
    assert report == {"output": str(out), "fibers": len(dwi_seq), "points": len(dwi_seq.get_data()),
                      "output_bytes": out.stat().st_size}
    back = nib.streamlines.load(str(out))
    if name.lower().endswith(".tck"):  # float32 points, stored as given
        assert_same_fibers(back.streamlines.get_data(), back.streamlines._lengths, dwi_seq)
    else:  # through the .trk's voxmm coordinates of the identity space (RAS+, 1 mm voxels)
        np.testing.assert_array_equal(back.header["voxel_to_rasmm"], np.eye(4))
        assert_same_fibers(back.streamlines.get_data(), back.streamlines._lengths, dwi_seq, atol=1e-4)
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]  # nothing else left behind


def test_save_trx_read_back_and_laid_out_as_the_specification_says(tmp_path, dwi_seq):
    out = tmp_path / "out.trx"
    report = fiblet.save(out, dwi_seq)
    assert report["fibers"] == len(dwi_seq) and report["points"] == len(dwi_seq.get_data())
    s, data = fiblet.read_streamlines(out)
    assert_same_fibers(s.points, s.lengths, dwi_seq)
    assert data == {}
    # The TRX specification (github.com/tee-ar-ex/trx-spec): a zip of
    # header.json and arrays named NAME[.COMPONENTS].DTYPE, little-endian.
    with zipfile.ZipFile(out) as z:
        header = json.loads(z.read("header.json"))
        assert header["NB_STREAMLINES"] == len(dwi_seq) and header["NB_VERTICES"] == len(dwi_seq.get_data())
        np.testing.assert_array_equal(header["VOXEL_TO_RASMM"], np.eye(4))
        assert list(header["DIMENSIONS"]) == [1, 1, 1]
        names = {n.split(".", 1)[0]: n for n in z.namelist()}
        _, components, dtype = names["positions"].split(".")
        assert components == "3"
        positions = np.frombuffer(z.read(names["positions"]), np.dtype(dtype).newbyteorder("<")).reshape(-1, 3)
        np.testing.assert_array_equal(positions, dwi_seq.get_data())
        offsets = np.frombuffer(z.read(names["offsets"]), np.dtype(names["offsets"].split(".")[1]).newbyteorder("<"))
    starts = np.concatenate([[0], np.cumsum(dwi_seq._lengths)])
    np.testing.assert_array_equal(offsets, starts[:len(offsets)])
    assert len(offsets) in (len(dwi_seq), len(dwi_seq) + 1)  # with or without the end sentinel


ZSTD_SKIPPABLE = struct.pack("<I", 0x184D2A50)  # the first frame of a .fftz (formats/fftz.md)


@pytest.mark.parametrize("ext", [".fft", ".fftz"])
def test_save_fft_and_fftz_compress_as_the_cli_does(tmp_path, shared, cli, dwi_seq, ext):
    out = tmp_path / f"points{ext}"
    report = fiblet.save(out, dwi_seq)
    head = out.read_bytes()[:12]
    if ext == ".fftz":
        assert head[:4] == ZSTD_SKIPPABLE and head[8:12] == b"FFTZ"
    else:
        assert head[0] == 2  # a version-2 .fft, no container
    worst = max_distance(fiblet.load(out), dwi_seq)
    assert worst <= report["max_error_um"] * 1e-3 * (1 + 1e-4) + 1e-7
    assert subprocess.run([cli, "verify", "-q", str(out)], capture_output=True).returncode == 0
    # From a file: the bytes of `fiblet compress` (with --zstd for .fftz).
    tck = shared / "dwi-small64d-ifod1.tck"
    fiblet.save(tmp_path / f"py{ext}", tck)
    subprocess.run([cli, "compress", "-q", str(tck), "-o", str(tmp_path / f"cli{ext}")]
                   + (["--zstd"] if ext == ".fftz" else []), check=True)
    assert (tmp_path / f"py{ext}").read_bytes() == (tmp_path / f"cli{ext}").read_bytes()


def test_save_fine_index_writes_what_compress_fine_index_does(tmp_path, shared, cli):
    # fine_index=True: the block index's version 4, byte for byte as `fiblet
    # compress --fine-index`; the default stays `fiblet compress`'s version 2.
    tck = shared / "dwi-small64d-ifod1.tck"
    fiblet.save(tmp_path / "py.fft", tck, fine_index=True)
    fiblet.save(tmp_path / "py-default.fft", tck)
    subprocess.run([cli, "compress", "-q", "--fine-index", str(tck), "-o", str(tmp_path / "cli.fft")], check=True)
    subprocess.run([cli, "compress", "-q", str(tck), "-o", str(tmp_path / "cli-default.fft")], check=True)
    assert (tmp_path / "py.fft").read_bytes() == (tmp_path / "cli.fft").read_bytes()
    assert (tmp_path / "py-default.fft").read_bytes() == (tmp_path / "cli-default.fft").read_bytes()
    assert (tmp_path / "py.fft").read_bytes() != (tmp_path / "py-default.fft").read_bytes()
    with pytest.raises(ValueError, match="fine_index"):
        fiblet.save(tmp_path / "out.tck", tck, fine_index=True)
    assert not (tmp_path / "out.tck").exists()


@pytest.mark.parametrize("name", ["out.vtk", "out.txt", "out", "out.fft.gz", "out.tck.bak", "out.nii"])
def test_save_refuses_other_extensions_and_writes_nothing(tmp_path, shared, name):
    fibers = [np.array([[0, 0, 0], [0.1, 0, 0], [0.2, 0, 0]], np.float32)]
    for streamlines in (fibers, shared / "dwi-small64d-ifod1.tck"):
        with pytest.raises(ValueError, match=r"must end in one of \.fft, \.fftz, \.tck, \.trk, \.trx") as e:
            fiblet.save(tmp_path / name, streamlines)
        assert repr(str(tmp_path / name)) in str(e.value)
    assert list(tmp_path.iterdir()) == []
    # An existing file of that name is left as it was, overwrite or not.
    (tmp_path / name).write_bytes(b"old")
    with pytest.raises(ValueError):
        fiblet.save(tmp_path / name, fibers, overwrite=True)
    assert (tmp_path / name).read_bytes() == b"old"


def test_save_to_tck_keeps_the_overwrite_rules(tmp_path):
    fibers = [np.array([[0, 0, 0], [0.1, 0, 0], [0.2, 0, 0]], np.float32)]
    out = tmp_path / "x.tck"
    out.write_bytes(b"old")
    with pytest.raises(FileExistsError):
        fiblet.save(out, fibers)
    assert out.read_bytes() == b"old"
    fiblet.save(out, fibers, overwrite=True)
    np.testing.assert_array_equal(nib.streamlines.load(str(out)).streamlines[0], fibers[0])
    # step= resamples for compression: refused where the points are written as they are.
    with pytest.raises(ValueError, match="step="):
        fiblet.save(tmp_path / "y.trk", fibers, step=0.5)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.tck"]


def test_save_of_a_file_converts_it_keeping_its_data(tmp_path, shared):
    src = shared / "conformance" / "complex.trk"
    s0, data0 = fiblet.read_streamlines(src)
    assert len(data0) == 5
    fiblet.save(tmp_path / "c.trx", src)
    s, data = fiblet.read_streamlines(tmp_path / "c.trx")
    np.testing.assert_array_equal(s.points, s0.points)
    np.testing.assert_array_equal(s.offsets, s0.offsets)
    assert data.keys() == data0.keys()
    for k in data0:
        np.testing.assert_array_equal(data[k], data0[k])
    # A .trk keeps the source's space and data, as nibabel reads them.
    fiblet.save(tmp_path / "c.trk", src)
    a, b = nib.streamlines.load(str(src)), nib.streamlines.load(str(tmp_path / "c.trk"))
    np.testing.assert_array_equal(b.header["voxel_to_rasmm"], a.header["voxel_to_rasmm"])
    np.testing.assert_allclose(b.streamlines.get_data(), a.streamlines.get_data(), rtol=0, atol=1e-4)
    assert b.tractogram.data_per_point.keys() == a.tractogram.data_per_point.keys()
    for k, v in a.tractogram.data_per_streamline.items():
        np.testing.assert_array_equal(b.tractogram.data_per_streamline[k], v)
    # A .tck holds points only: said, not silent.
    with pytest.warns(UserWarning, match="holds points only"):
        fiblet.save(tmp_path / "c.tck", src)
    np.testing.assert_allclose(nib.streamlines.load(str(tmp_path / "c.tck")).streamlines.get_data(),
                               a.streamlines.get_data(), rtol=0, atol=1e-4)


def test_save_sizes_resampled_point_data_against_max_memory(tmp_path):
    """A TRX whose 400 kB of per-point values would take 1.9 GB once its
    20 m segment is resampled: refused before anything is allocated or
    written, with the budget in the message; within the budget it is saved."""
    def trx(name, length, components):
        root = tmp_path / name
        (root / "dpv").mkdir(parents=True)
        (root / "header.json").write_text(json.dumps({
            "VOXEL_TO_RASMM": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], "DIMENSIONS": [10, 10, 10],
            "NB_STREAMLINES": 2, "NB_VERTICES": 4}))
        np.array([[0, 0, 0], [1, 0, 0], [length, 0, 0], [5, 5, 5]], np.float32).tofile(root / "positions.3.float32")
        np.array([0, 3], np.uint32).tofile(root / "offsets.uint32")
        np.full((4, components), 7, np.uint8).tofile(root / "dpv" / f"x.{components}.uint8")
        return str(root)

    out = tmp_path / "big.fft"
    with pytest.raises(fiblet.FibletError, match=r"memory budget of 1024 MiB; max_memory="):
        fiblet.save(out, trx("big.trx", 20000, 100000), max_memory=1 << 30)
    assert not out.exists()
    with pytest.raises(ValueError):
        fiblet.save(out, trx("bad.trx", 20, 2), max_memory=-1)
    report = fiblet.save(tmp_path / "small.fft", trx("small.trx", 2000, 50), max_memory=64 << 20)
    assert report["points"] > 1000
    streamlines, data = fiblet.load(tmp_path / "small.fft", data=True)
    assert data["dpv/x"].dtype == np.uint8 and data["dpv/x"].shape == (len(streamlines._data), 50)
    assert (data["dpv/x"] == 7).all()
