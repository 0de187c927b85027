"""The data a .fft keeps from a .trk or TRX source, in Python as DIPY and
nibabel users expect it: load(data=True), read_streamlines of a .fft and
load_sft's data_per_streamline / data_per_point against nibabel's reading of
the source .trk (written here by nibabel, an independent writer), aligned
with fibers=/roi= subsets; load_sft(reference="same") against nibabel's
header of the .trk and DIPY's load_tractogram; DIPY's bounding-box check."""
import numpy as np
import pytest

import fiblet

nib = pytest.importorskip("nibabel")
from nibabel.streamlines.trk import Field  # noqa: E402

from test_formats import cubic_offset_bound, trx_write  # noqa: E402

STEP = 0.5
AFFINE = np.array([[-2.0, 0, 0, 90], [0, 2.0, 0, -126], [0, 0, 2.5, -72], [0, 0, 0, 1]])
DIMS = (91, 109, 73)
DPS = ("weight", "id", "rgb")  # float32, integer values, 3 components
DPP = ("fa", "dir")            # 1 and 3 components


def fixed_step_fibers(rng, count):
    """Fibers at exactly STEP mm between points (a slowly turning direction)."""
    fibers = []
    for _ in range(count):
        n = int(rng.integers(20, 80))
        d = np.cumsum(rng.normal(0, 0.15, (n - 1, 3)), axis=0) + rng.normal(0, 1, 3)
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        fibers.append(rng.uniform(-30, 30, 3) + np.concatenate([[np.zeros(3)], np.cumsum(STEP * d, axis=0)]))
    return [f.astype(np.float32) for f in fibers]


def write_trk(path, fibers, rng, affine=AFFINE, dims=DIMS):
    """A .trk written by nibabel, with 3 per-streamline and 2 per-point fields."""
    tg = nib.streamlines.Tractogram(fibers, affine_to_rasmm=np.eye(4))
    n = len(fibers)
    tg.data_per_streamline["weight"] = rng.uniform(0, 1, (n, 1)).astype(np.float32)
    tg.data_per_streamline["id"] = (np.arange(n) * 7 + 3)[:, None]
    tg.data_per_streamline["rgb"] = rng.integers(0, 256, (n, 3)).astype(np.float32)
    tg.data_per_point["fa"] = [rng.uniform(0, 1, (len(f), 1)).astype(np.float32) for f in fibers]
    tg.data_per_point["dir"] = [np.gradient(f, axis=0) for f in fibers]
    header = {Field.VOXEL_TO_RASMM: affine, Field.DIMENSIONS: np.array(dims, np.int16),
              Field.VOXEL_SIZES: np.abs(np.diag(affine)[:3]).astype(np.float32), Field.VOXEL_ORDER: "LAS"}
    nib.streamlines.save(tg, str(path), header=header)
    return nib.streamlines.load(str(path))


@pytest.fixture(scope="module")
def trk(tmp_path_factory):
    """(trk path, nibabel's TrkFile of it, .fft path, compress report): a fixed step, not resampled."""
    tmp = tmp_path_factory.mktemp("data")
    rng = np.random.default_rng(31)
    trk_file = write_trk(tmp / "in.trk", fixed_step_fibers(rng, 30), rng)
    report = fiblet.save(tmp / "in.fft", tmp / "in.trk")
    assert not report["resampled"], "the fixed-step input was resampled"
    return tmp / "in.trk", trk_file, tmp / "in.fft", report


def within_error(got, ref, report):
    """Same fiber count and point counts, every point within the recorded error."""
    assert len(got) == len(ref)
    assert [len(a) for a in got] == [len(b) for b in ref]
    bound = report["max_error_um"] * 1e-3 * (1 + 1e-4) + 1e-6
    dist = np.linalg.norm(np.concatenate(list(got)) - np.concatenate(list(ref)), axis=1)
    assert dist.max() <= bound


def expected(trk_file):
    """What load(data=True) must give for the .trk's data, by nibabel."""
    tg = trk_file.tractogram
    want = {f"dps/{k}": np.asarray(v) for k, v in tg.data_per_streamline.items()}
    want.update({f"dpv/{k}": v.get_data() for k, v in tg.data_per_point.items()})
    return want


def assert_same_data(got, want):
    assert set(got) == set(want)
    for name in want:
        assert got[name].dtype == want[name].dtype, name
        assert got[name].shape == want[name].shape, name
        np.testing.assert_array_equal(got[name], want[name], err_msg=name)


def test_load_data_equals_nibabels_reading_of_the_trk(trk):
    _, trk_file, fft, report = trk
    s, data = fiblet.load(fft, data=True)
    within_error(s, trk_file.streamlines, report)
    want = expected(trk_file)
    assert set(want) == {f"dps/{k}" for k in DPS} | {f"dpv/{k}" for k in DPP}
    assert want["dps/rgb"].shape == (30, 3) and want["dpv/dir"].shape == (s.total_nb_rows, 3)
    assert_same_data(data, want)
    np.testing.assert_array_equal(data["dps/id"][:, 0], np.arange(30) * 7 + 3)
    plain = fiblet.load(fft)  # data=False: the Streamlines alone, the same points
    assert isinstance(plain, fiblet.Streamlines)
    np.testing.assert_array_equal(plain.points, s.points)


def test_read_streamlines_decodes_fft_and_fftz(trk, tmp_path):
    trk_path, trk_file, fft, report = trk
    fiblet.save(tmp_path / "in.fftz", trk_path)
    source_points, source_data = fiblet.read_streamlines(trk_path)
    for path in (fft, tmp_path / "in.fftz"):
        s, data = fiblet.read_streamlines(path)
        within_error(s, trk_file.streamlines, report)
        assert_same_data(data, source_data)
        assert_same_data(data, expected(trk_file))
    # Recognised by content, not by name.
    renamed = tmp_path / "in.dat"
    renamed.write_bytes(fft.read_bytes())
    s, data = fiblet.read_streamlines(renamed)
    assert_same_data(data, source_data)


def fields_of(full, s_full, ids):
    """The rows of the full file's arrays for fibers `ids` (in that order), by hand."""
    out = {}
    for name, a in full.items():
        if name.startswith("dps/"):
            out[name] = np.stack([a[i] for i in ids]) if len(ids) else a[:0]
        elif name.startswith("dpv/"):
            parts = [a[s_full.offsets[i]:s_full.offsets[i + 1]] for i in ids]
            out[name] = np.concatenate(parts) if parts else a[:0]
    return out


def test_subset_data_follows_the_returned_fibers(trk):
    _, _, fft, _ = trk
    s_full, full = fiblet.load(fft, data=True)
    lengths = s_full.lengths
    center = s_full[4][len(s_full[4]) // 2]
    cases = [dict(fibers=[5, 2, 2, -1]), dict(fibers=slice(10, 17)), dict(fibers=lengths > 50),
             dict(roi=(*center, 4.0)), dict(fibers=range(0, 30, 3), roi=(*center, 20.0)), dict(fibers=[])]
    for kw in cases:
        s, data = fiblet.load(fft, data=True, **kw)
        ids = list(s.fiber_ids)
        for i, f in zip(ids, s):
            np.testing.assert_array_equal(f, s_full[i])
        want = fields_of(full, s_full, ids)
        assert_same_data(data, want)
        for name in data:  # aligned: one dps row per fiber, one dpv row per point
            assert len(data[name]) == (len(s) if name.startswith("dps/") else s.total_nb_rows), (kw, name)
    assert len(fiblet.load(fft, roi=(*center, 4.0))) < 30  # the roi case is a real subset


def test_trx_groups_and_dtypes_follow_a_subset(tmp_path, cli):
    rng = np.random.default_rng(5)
    fibers = fixed_step_fibers(rng, 6)
    n_points = sum(len(f) for f in fibers)
    arrays = {"dps/label": np.array([3, -1, 4, 1, -5, 9], np.int16), "dpv/t": rng.normal(size=n_points),
              "groups/A": np.array([0, 2, 4], np.uint32), "groups/B": np.array([1], np.uint32),
              "dpg/A/volume": np.array([2.5], np.float32)}
    trx_write(tmp_path / "g.trx", fibers, arrays, positions="float32")
    report = fiblet.save(tmp_path / "g.fft", tmp_path / "g.trx")
    assert not report["resampled"]
    s, full = fiblet.load(tmp_path / "g.fft", data=True)
    assert full["dps/label"].dtype == np.int16 and full["dpv/t"].dtype == np.float64
    for name, a in arrays.items():
        np.testing.assert_array_equal(full[name], a.reshape(len(a), -1), err_msg=name)
    sub, data = fiblet.load(tmp_path / "g.fft", data=True, fibers=[4, 1, 0, 4])
    np.testing.assert_array_equal(data["dps/label"][:, 0], [-5, -1, 3, -5])
    # Groups list positions in the returned fibers: 4, 0, 4 are in A; 1 in B.
    np.testing.assert_array_equal(data["groups/A"][:, 0], [0, 2, 3])
    np.testing.assert_array_equal(data["groups/B"][:, 0], [1])
    assert data["groups/A"].dtype == np.uint32
    np.testing.assert_array_equal(data["dpg/A/volume"], [[2.5]])
    np.testing.assert_array_equal(data["dpv/t"], np.concatenate([full["dpv/t"][s.offsets[i]:s.offsets[i + 1]]
                                                                 for i in (4, 1, 0, 4)]))


def test_resampled_file_gives_point_data_of_the_encoded_points(tmp_path):
    """Variable spacing: the .fft holds new points, and per-point arrays re-made
    for them (float32, linear between the input points around each new point):
    a value equal to x + 2y stays within the point error plus the cubic's
    offset from its chord of the decoded x + 2y; per-streamline arrays are
    the source's, unchanged; a subset takes the same rows."""
    rng = np.random.default_rng(7)
    fibers = []
    for _ in range(20):
        steps = rng.uniform(0.2, 1.4, size=(50, 1)) * np.array([[1.0, 0.3, 0.1]]) + rng.normal(0, 0.05, (50, 3))
        fibers.append((np.cumsum(steps, axis=0) + rng.uniform(-20, 20, 3)).astype(np.float32))
    tg = nib.streamlines.Tractogram(fibers, affine_to_rasmm=np.eye(4))
    tg.data_per_point["lin"] = [(f[:, 0] + 2 * f[:, 1]).astype(np.float32)[:, None] for f in fibers]
    tg.data_per_streamline["id"] = np.arange(20, dtype=np.float32)[:, None]
    nib.streamlines.save(tg, str(tmp_path / "var.trk"))
    report = fiblet.save(tmp_path / "var.fft", tmp_path / "var.trk")
    assert report["resampled"] and fiblet.info(tmp_path / "var.fft")["resampled"]
    s, data = fiblet.load(tmp_path / "var.fft", data=True)
    assert data["dpv/lin"].dtype == np.float32 and data["dpv/lin"].shape == (s.total_nb_rows, 1)
    assert s.total_nb_rows != sum(len(f) for f in fibers)  # new points, other counts
    for f_in, f, v in zip(fibers, s, np.split(data["dpv/lin"][:, 0], s.offsets[1:-1])):
        bound = (report["max_error_um"] * 1e-3 + cubic_offset_bound(f_in)) * 3 + 1e-3
        np.testing.assert_allclose(v, f[:, 0] + 2 * f[:, 1], rtol=0, atol=bound)
    np.testing.assert_array_equal(data["dps/id"], tg.data_per_streamline["id"])
    sub, sub_data = fiblet.load(tmp_path / "var.fft", data=True, fibers=[7, 3])
    np.testing.assert_array_equal(sub_data["dpv/lin"], np.concatenate([data["dpv/lin"][s.offsets[i]:s.offsets[i + 1]]
                                                                       for i in (7, 3)]))


def test_data_of_a_tck_made_file_and_refusals(tmp_path, trk):
    _, _, fft, _ = trk
    fiblet.save(tmp_path / "p.fft", [np.array([[0, 0, 0], [0, 0, 1], [0, 0, 2]], np.float32)])
    s, data = fiblet.load(tmp_path / "p.fft", data=True)
    assert data == {} and len(s) == 1
    with pytest.raises(ValueError, match="ignore_trailer"):
        fiblet.load(fft, data=True, ignore_trailer=True)


# ---- load_sft: DIPY's reference="same", bounding-box check, spaces ----

def test_load_sft_same_is_the_trk_space_with_its_data(trk):
    pytest.importorskip("dipy")
    from dipy.io.stateful_tractogram import Origin, Space
    from dipy.io.streamline import load_tractogram

    trk_path, trk_file, fft, report = trk
    sft = fiblet.load_sft(fft, "same")
    header = trk_file.header
    np.testing.assert_array_equal(sft.affine, header[Field.VOXEL_TO_RASMM])
    np.testing.assert_array_equal(sft.dimensions, header[Field.DIMENSIONS])
    np.testing.assert_array_equal(sft.voxel_sizes, header[Field.VOXEL_SIZES])
    assert sft.voxel_order == "LAS"
    assert sft.space == Space.RASMM and sft.origin == Origin.NIFTI and sft.is_bbox_in_vox_valid()
    theirs = load_tractogram(str(trk_path), "same")
    for a, b in zip(sft.space_attributes, theirs.space_attributes):
        np.testing.assert_array_equal(a, b)
    within_error(sft.streamlines, theirs.streamlines, report)
    assert set(sft.data_per_streamline) == set(DPS) and set(sft.data_per_point) == set(DPP)
    for k in DPS:
        np.testing.assert_array_equal(sft.data_per_streamline[k], theirs.data_per_streamline[k])
    for k in DPP:
        assert len(sft.data_per_point[k]) == len(theirs.data_per_point[k])
        for a, b in zip(sft.data_per_point[k], theirs.data_per_point[k]):
            np.testing.assert_array_equal(a, b)
    # to_space / to_origin as load_tractogram's.
    vox = fiblet.load_sft(fft, "same", to_space=Space.VOX, to_origin="trackvis")
    theirs_vox = load_tractogram(str(trk_path), "same", to_space=Space.VOX, to_origin=Origin.TRACKVIS)
    assert vox.space == Space.VOX and vox.origin == Origin.TRACKVIS
    bound_vox = report["max_error_um"] * 1e-3 / 2.0 + 1e-4  # 2 mm and 2.5 mm voxels
    assert np.abs(vox.streamlines.get_data() - theirs_vox.streamlines.get_data()).max() <= bound_vox
    # A subset keeps its data aligned.
    sub = fiblet.load_sft(fft, "same", fibers=[3, 1])
    np.testing.assert_array_equal(sub.data_per_streamline["id"][:, 0], [3 * 7 + 3, 1 * 7 + 3])
    np.testing.assert_array_equal(sub.data_per_point["fa"][1], theirs.data_per_point["fa"][1])


def test_load_sft_same_needs_a_file_that_keeps_a_space(tmp_path):
    pytest.importorskip("dipy")
    fiblet.save(tmp_path / "p.fft", [np.array([[0, 0, 0], [0, 0, 1], [0, 0, 2]], np.float32)])
    with pytest.raises(ValueError, match="no reference space"):
        fiblet.load_sft(tmp_path / "p.fft", "same")


def test_load_sft_checks_the_bounding_box_as_dipy(trk, tmp_path):
    pytest.importorskip("dipy")
    from dipy.io.streamline import load_tractogram

    trk_path, _, fft, _ = trk
    far = AFFINE.copy()
    far[:3, 3] += [300.0, 0, 0]  # the same grid 300 mm to the left
    ref = tmp_path / "far.nii.gz"
    nib.Nifti1Image(np.zeros(DIMS, np.float32), far).to_filename(str(ref))
    with pytest.raises(ValueError, match="(?i)bounding box"):
        load_tractogram(str(trk_path), str(ref), trk_header_check=False)  # DIPY refuses it too
    with pytest.raises(ValueError, match="bbox_valid_check=False"):
        fiblet.load_sft(fft, ref)
    sft = fiblet.load_sft(fft, ref, bbox_valid_check=False)
    assert len(sft.streamlines) == 30 and not sft.is_bbox_in_vox_valid()
    np.testing.assert_array_equal(sft.affine, far)
    # The file's own grid passes.
    near = tmp_path / "near.nii.gz"
    nib.Nifti1Image(np.zeros(DIMS, np.float32), AFFINE).to_filename(str(near))
    assert fiblet.load_sft(fft, near).is_bbox_in_vox_valid()
