"""The Python API as DIPY / nibabel users type it: Streamlines indexing like
nibabel's ArraySequence, fibers= masks, roi= as numbers, arrays and image
masks (against a numpy reimplementation of tckedit's voxel rule and the
CLI), clear argument errors, a clean namespace, and load_sft()."""
import subprocess

import numpy as np
import pytest

import fiblet

nib = pytest.importorskip("nibabel")


@pytest.fixture(scope="module")
def dwi(compressed):
    fft, tck = compressed("dwi-small64d-ifod1")
    return fft, tck, fiblet.load(fft)


def assert_same_fibers(got, ref, ids):
    assert isinstance(got, fiblet.Streamlines)
    assert list(got.fiber_ids) == list(ids)
    assert len(got) == len(ref)
    for a, b in zip(got, ref):
        np.testing.assert_array_equal(a, b)


def test_streamlines_index_like_array_sequence(dwi):
    _, _, full = dwi
    seq = full.to_array_sequence()
    n = len(full)
    mask = full.lengths > np.median(full.lengths)
    for key in [slice(10, 40), slice(None, None, 3), slice(-5, None), slice(50, 10, -4), slice(7, 7),
                [5, 3, 3, -1], np.array([0, 1, 2, 50]), mask, np.arange(n) % 7 == 0]:
        assert_same_fibers(full[key], seq[key], np.arange(n)[key])
    # Selections compose, and fiber_ids stay the file's.
    assert list(full[10:40][[0, 2]].fiber_ids) == [10, 12]
    assert list(full[mask][:3].fiber_ids) == list(np.flatnonzero(mask)[:3])
    # A step-1 slice is a view, as ArraySequence slices are.
    assert np.shares_memory(full[10:40].points, full.points)
    assert full[3].shape == seq[3].shape and full[np.int64(3)].shape == seq[3].shape
    with pytest.raises(IndexError):
        full[[n]]
    with pytest.raises(IndexError):
        full[np.ones(n - 1, dtype=bool)]
    with pytest.raises(TypeError):
        full[[0.5]]


def assert_same_members(got, ref):
    """Every ArraySequence member of a fiblet.Streamlines against nibabel's."""
    assert len(got) == len(ref)
    for name in ("_data", "_offsets", "_lengths"):
        a, b = getattr(got, name), getattr(ref, name)
        assert a.dtype == b.dtype and a.shape == b.shape, name
        np.testing.assert_array_equal(a, b, err_msg=name)
    assert got.total_nb_rows == ref.total_nb_rows and type(got.total_nb_rows) is type(ref.total_nb_rows)
    assert got.common_shape == ref.common_shape
    assert got.is_sliced_view == ref.is_sliced_view and got.is_array_sequence
    np.testing.assert_array_equal(got.get_data(), ref.get_data())
    assert got.get_data().dtype == ref.get_data().dtype
    for a, b in zip(got, ref):
        np.testing.assert_array_equal(a, b)
    # nibabel's own offsets/lengths relation holds: fiber i is _data[_offsets[i]:][:_lengths[i]].
    for i in range(len(got)):
        np.testing.assert_array_equal(got._data[got._offsets[i]:got._offsets[i] + got._lengths[i]], got[i])


def test_streamlines_members_are_array_sequences(dwi):
    from nibabel.streamlines import ArraySequence

    _, _, full = dwi
    part = full[:40]
    ref = ArraySequence(list(part))  # nibabel's, built from the same fibers
    got = part.copy()
    assert_same_members(got, ref)
    assert_same_members(full, full.to_array_sequence())
    assert list(got.offsets) == list(ref._offsets) + [ref.total_nb_rows]  # ours: F + 1, the TRX layout
    # get_data() and copy() are copies.
    data = got.get_data()
    data[0] = 1e6
    assert got.points[0, 0] != 1e6
    clone = got.copy()
    clone.points[0] = -1e6
    assert got.points[0, 0] != -1e6 and not np.shares_memory(clone.points, got.points)
    assert list(clone.fiber_ids) == list(got.fiber_ids)
    # append and extend, with nibabel's rules: empty elements are skipped,
    # other shapes refused, float64 cast to float32, finalize_append after cache_build.
    rng = np.random.default_rng(3)
    new = [rng.normal(size=(n, 3)) for n in (4, 1, 9)]
    for seq in (got, ref):
        seq.append(new[0])
        seq.append(np.zeros((0, 3)))
        seq.extend([new[1], np.zeros((0, 3)), new[2]])
        seq.extend(ArraySequence(new[:2]))
        seq.extend(f for f in new[1:])
        seq.append(new[2], cache_build=True)
        seq.append(new[0], cache_build=True)
        seq.finalize_append()
        with pytest.raises(ValueError):
            seq.append(np.zeros((2, 4)))
    assert_same_members(got, ref)
    assert len(got) == 40 + 9
    assert list(got.fiber_ids[:40]) == list(range(40)) and set(got.fiber_ids[40:]) == {-1}
    np.testing.assert_array_equal(got[-1], new[0].astype(np.float32))
    # A sequence grown from nothing (of float32 fibers: nibabel's takes the
    # first element's dtype, ours stays float32).
    empty, nib_empty = fiblet.Streamlines(np.zeros((0, 3), np.float32), np.zeros(1, np.int64)), ArraySequence()
    for seq in (empty, nib_empty):
        seq.extend([f.astype(np.float32) for f in new])
    assert_same_members(empty, nib_empty)
    # A slice's _data holds only its fibers (nibabel's keeps the parent's,
    # is_sliced_view True): the same fibers, get_data() and total_nb_rows.
    seq = full.to_array_sequence()
    sl, nib_sl = full[100:120], seq[100:120]
    assert nib_sl.is_sliced_view and not sl.is_sliced_view and sl._offsets[0] == 0
    np.testing.assert_array_equal(sl.get_data(), nib_sl.get_data())
    assert sl.total_nb_rows == nib_sl.total_nb_rows
    np.testing.assert_array_equal(sl._lengths, nib_sl._lengths)
    assert_same_members(sl.copy(), nib_sl.copy())


def test_fibers_accepts_boolean_masks(dwi):
    fft, _, full = dwi
    mask = full.lengths > 60
    s = fiblet.load(fft, fibers=mask)
    assert_same_fibers(s, full[mask], np.flatnonzero(mask))
    assert 0 < mask.sum() < len(full)
    with pytest.raises(IndexError):
        fiblet.load(fft, fibers=mask[:-1])


def nifti_mask(path, data, affine):
    nib.Nifti1Image(data.astype(np.float32), affine).to_filename(str(path))
    return path


def brute_force_mask(full, data, affine):
    """tckedit's rule, restated: the nearest voxel's value rounds to non-zero."""
    to_vox = np.linalg.inv(affine)
    keep = []
    for i, f in enumerate(full):
        v = np.rint(f.astype(np.float64) @ to_vox[:3, :3].T + to_vox[:3, 3]).astype(np.int64)
        ok = np.all((v >= 0) & (v < data.shape), axis=1)
        vals = np.zeros(len(f))
        vals[ok] = data[v[ok, 0], v[ok, 1], v[ok, 2]]
        if np.any(np.isfinite(vals) & (np.abs(vals) >= 0.5)):
            keep.append(i)
    return keep


def test_roi_as_numbers_arrays_and_image_masks(dwi, tmp_path, cli):
    fft, _, full = dwi
    c = full[10][len(full[10]) // 2].astype(np.float64)
    sphere = fiblet.load(fft, roi=fiblet.Sphere(c, 2.0))
    assert 0 < len(sphere) < len(full)
    for roi in [(c[0], c[1], c[2], 2.0), list(c) + [2.0], np.append(c, 2.0)]:
        assert list(fiblet.load(fft, roi=roi).fiber_ids) == list(sphere.fiber_ids)
    box = fiblet.load(fft, roi=fiblet.Box(c - 2, c + 2))
    corners = np.concatenate([c + 2, c - 2])  # either order, as the CLI
    assert list(fiblet.load(fft, roi=tuple(corners)).fiber_ids) == list(box.fiber_ids)
    both = fiblet.load(fft, roi=[fiblet.Sphere(c, 2.0), fiblet.Box(c - 2, c + 2)])
    rows = fiblet.load(fft, roi=np.array([list(c) + [2.0], list(c) + [3.0]]))  # one region per row
    assert list(rows.fiber_ids) == list(sphere.fiber_ids)
    assert set(both.fiber_ids) == set(sphere.fiber_ids) & set(box.fiber_ids)

    # An image mask over the data set's box: 1 mm voxels, a 6 mm cube of
    # ones around c, a shell of 0.4 (not inside) and one voxel of 0.6 (inside).
    affine = np.diag([1.0, 1.0, 1.0, 1.0])
    affine[:3, 3] = np.floor(c) - 10
    data = np.zeros((21, 21, 21))
    data[7:14, 7:14, 7:14] = 0.4
    data[8:13, 8:13, 8:13] = 1.0
    data[3, 3, 3] = 0.6
    path = nifti_mask(tmp_path / "mask.nii.gz", data, affine)
    expected = brute_force_mask(full, data, affine)
    assert 0 < len(expected) < len(full)
    for roi in [str(path), path, fiblet.Mask(path)]:
        assert list(fiblet.load(fft, roi=roi).fiber_ids) == expected
    outside = [i for i in range(len(full)) if i not in expected]
    assert list(fiblet.load(fft, roi=fiblet.Mask(path, exclude=True)).fiber_ids) == outside
    # Index lists keep their order and repeats, on both paths (a small
    # include region goes through the block index; an exclude-only query
    # decodes everything and tests points).
    order = [expected[-1], outside[1], expected[0], expected[-1], outside[0], outside[1]]
    for roi, rule in [(path, lambda i: i in expected), (fiblet.Mask(path, exclude=True), lambda i: i not in expected)]:
        ids = [i for i in order if rule(i)]
        assert len(ids) == 3
        assert_same_fibers(fiblet.load(fft, roi=roi, fibers=order), [full[i] for i in ids], ids)
    # The CLI gives the same fibers.
    out = tmp_path / "cli.tck"
    subprocess.run([cli, "extract", "-q", str(fft), "-o", str(out), "--include", str(path)], check=True)
    cli_fibers = nib.streamlines.load(str(out)).streamlines
    assert_same_fibers(fiblet.load(fft, roi=path), cli_fibers, expected)


def test_clear_argument_errors(dwi, tmp_path):
    fft, _, _ = dwi
    with pytest.raises(FileNotFoundError, match="x.trk"):  # a file name is a tractogram to compress
        fiblet.save(tmp_path / "a.fft", tmp_path / "x.trk")
    with pytest.raises(TypeError, match="streamlines must be"):
        fiblet.save(tmp_path / "a.fft", 5)
    with pytest.raises(TypeError, match="streamline 0"):
        fiblet.save(tmp_path / "a.fft", [[["a", "b", "c"]]])
    with pytest.raises(ValueError, match="streamline 0"):
        fiblet.save(tmp_path / "a.fft", [np.zeros((3, 2))])
    with pytest.raises(TypeError, match="path must be"):
        fiblet.save(5, [np.zeros((3, 3))])
    with pytest.raises(ValueError, match="4 .* or 6"):
        fiblet.load(fft, roi=(1, 2, 3))
    with pytest.raises(TypeError, match="a region is"):
        fiblet.load(fft, roi=object())
    with pytest.raises(FileNotFoundError):
        fiblet.load(fft, roi=tmp_path / "missing.nii")
    bad = tmp_path / "bad.nii"
    bad.write_bytes(b"\x00" * 400)
    with pytest.raises(fiblet.FibletError) as e:
        fiblet.load(fft, roi=bad)
    assert e.value.category == "image_format" and "bad.nii" in str(e.value)
    assert not (tmp_path / "a.fft").exists()


def test_namespace_is_the_api():
    public = {name for name in dir(fiblet) if not name.startswith("_")} - {"nibabel_format"}  # the submodule
    assert public == set(fiblet.__all__)
    for leaked in ["np", "os", "tempfile", "dataclass", "numbers"]:
        assert not hasattr(fiblet, leaked), leaked
    namespace = {}
    exec("from fiblet import *", namespace)  # every name of __all__ exists
    assert set(namespace) - {"__builtins__"} == set(fiblet.__all__)


def test_load_sft_is_dipys_stateful_tractogram(dwi, tmp_path):
    pytest.importorskip("dipy")
    from dipy.io.stateful_tractogram import Space, StatefulTractogram
    from dipy.io.streamline import load_tractogram

    fft, tck, _ = dwi
    # A reference grid around the data set (2 mm voxels).
    affine = np.diag([2.0, 2.0, 2.0, 1.0])
    affine[:3, 3] = [-4.0, -4.0, 0.0]
    ref = tmp_path / "ref.nii.gz"
    nib.Nifti1Image(np.zeros((20, 20, 20), np.float32), affine).to_filename(str(ref))
    sft = fiblet.load_sft(fft, ref)
    assert isinstance(sft, StatefulTractogram) and sft.space == Space.RASMM
    assert sft.is_bbox_in_vox_valid()
    np.testing.assert_allclose(sft.affine, affine)
    theirs = load_tractogram(str(tck), str(ref), bbox_valid_check=False)
    assert len(sft.streamlines) == len(theirs.streamlines)
    bound = fiblet.info(fft)["max_error_um"] * 1e-3 * (1 + 1e-4) + 1e-7
    assert np.linalg.norm(sft.streamlines.get_data() - theirs.streamlines.get_data(), axis=1).max() <= bound
    sub = fiblet.load_sft(fft, str(ref), fibers=slice(0, 5))
    assert len(sub.streamlines) == 5
