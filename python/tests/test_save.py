"""fiblet.save: streamlines from Python objects into .fft, read back and
measured against the points given."""
import json
import subprocess

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


def test_save_report_has_the_cli_json_keys(tmp_path, shared, cli):
    tck = shared / "dwi-small64d-ifod1.tck"
    cli_report = json.loads(subprocess.run([cli, "compress", "--json", "-q", str(tck), "-o", str(tmp_path / "c.fft")],
                                           check=True, capture_output=True, text=True).stdout)
    py_report = fiblet.save(tmp_path / "p.fft", nib.streamlines.load(str(tck)).streamlines)
    assert set(py_report) == set(cli_report)
    for key in ("fibers", "points", "blocks", "max_error_um", "mean_error_um", "step_mm"):
        assert py_report[key] == pytest.approx(cli_report[key], rel=1e-6), key
