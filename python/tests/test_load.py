"""fiblet.load and its nibabel helpers, against nibabel's own reading of the
source .tck files."""
import subprocess

import numpy as np
import pytest

import fiblet

nib = pytest.importorskip("nibabel")


def recorded_bound_mm(fft):
    # The header's max error is stored as float32: allow its rounding.
    return fiblet.info(fft)["max_error_um"] * 1e-3 * (1 + 1e-4) + 1e-7


def assert_matches(streamlines, reference_seq, bound_mm):
    assert len(streamlines) == len(reference_seq)
    np.testing.assert_array_equal(streamlines.lengths, reference_seq._lengths)
    ref_points = reference_seq.get_data()
    dist = np.linalg.norm(streamlines.points.astype(np.float64) - ref_points, axis=1)
    assert dist.max() <= bound_mm
    return dist


@pytest.mark.parametrize("name", ["small-sdstream", "dwi-small64d-ifod1"])
def test_load_matches_nibabel_within_recorded_error(compressed, name):
    fft, tck = compressed(name)
    s = fiblet.load(fft)
    assert s.points.dtype == np.float32 and s.points.shape == (s.offsets[-1], 3)
    assert s.points.flags.c_contiguous
    assert s.offsets.dtype == np.int64 and s.offsets[0] == 0
    dist = assert_matches(s, nib.streamlines.load(str(tck)).streamlines, recorded_bound_mm(fft))
    # The error is real (lossy codec) yet small: not an accidental copy of the input.
    assert 0 < dist.max() < 0.05


def test_file_written_by_the_reference_encoder(shared):
    # data/reference/*.fft come from the Fiblets paper's encoder, not fiblet.
    fft = shared / "reference" / "small-sdstream.fft"
    s = fiblet.load(fft)
    # That encoder's recorded max is 13.078 um for a true 13.097 um (float
    # rounding order, see shared/data/README.md): allow 0.5 %.
    bound = fiblet.info(fft)["max_error_um"] * 1e-3 * 1.005
    assert_matches(s, nib.streamlines.load(str(shared / "small-sdstream.tck")).streamlines, bound)


def test_points_are_not_copied(compressed):
    fft, _ = compressed("dwi-small64d-ifod1")
    s = fiblet.load(fft)
    # numpy views the decoder's buffer (kept alive by a capsule), it did not copy it.
    assert not s.points.flags.owndata and type(s.points.base).__name__ == "PyCapsule"
    assert s.points.flags.writeable
    seq = s.to_array_sequence()
    assert np.shares_memory(seq._data, s.points)
    del s
    assert seq[3].shape[1] == 3 and np.isfinite(seq.get_data()).all()  # buffer outlives the Streamlines


def test_load_tractogram_and_array_sequence(compressed):
    fft, tck = compressed("dwi-small64d-ifod1")
    ref = nib.streamlines.load(str(tck)).tractogram
    t = fiblet.load_tractogram(fft)
    assert isinstance(t, nib.streamlines.Tractogram)
    np.testing.assert_array_equal(t.affine_to_rasmm, np.eye(4))
    bound = recorded_bound_mm(fft)
    for mine, theirs in zip(t.streamlines, ref.streamlines):
        assert mine.shape == theirs.shape
        assert np.linalg.norm(mine - theirs, axis=1).max() <= bound
    seq = fiblet.load_array_sequence(fft, fibers=[7])
    assert len(seq) == 1 and seq[0].shape == ref.streamlines[7].shape


def test_fiber_subsets_equal_slices_of_the_full_decode(compressed):
    fft, _ = compressed("dwi-small64d-ifod1")
    full = fiblet.load(fft)
    n = len(full)
    cases = {
        "range": (range(10, 40), list(range(10, 40))),
        "slice": (slice(100, None), list(range(100, n))),
        "negative slice": (slice(-5, None), list(range(n - 5, n))),
        "strided": (slice(1, 30, 7), list(range(1, 30, 7))),
        "list": ([5, 3, 4, 4, 80, -1], [5, 3, 4, 4, 80, n - 1]),
        "array": (np.array([0, 1, 2, 50]), [0, 1, 2, 50]),
        "int": (9, [9]),
        "empty": ([], []),
    }
    for label, (fibers, expected_ids) in cases.items():
        s = fiblet.load(fft, fibers=fibers)
        assert list(s.fiber_ids) == expected_ids, label
        assert len(s) == len(expected_ids), label
        for mine, i in zip(s, expected_ids):
            np.testing.assert_array_equal(mine, full[i], err_msg=label)


def test_bad_fiber_indices(compressed):
    fft, _ = compressed("dwi-small64d-ifod1")
    n = fiblet.info(fft)["fibers"]
    with pytest.raises(IndexError):
        fiblet.load(fft, fibers=[0, n])
    with pytest.raises(IndexError):
        fiblet.load(fft, fibers=[-n - 1])
    with pytest.raises(TypeError):
        fiblet.load(fft, fibers=[0.5])


def brute_force_roi(full, include=(), exclude=()):
    kept = []
    for i, f in enumerate(full):
        if all(r(f).any() for r in include) and not any(r(f).any() for r in exclude):
            kept.append(i)
    return kept


def test_roi_selection_equals_brute_force(compressed):
    fft, _ = compressed("dwi-small64d-ifod1")
    full = fiblet.load(fft)
    # Regions around points of two fibers, sized to catch some fibers only.
    c = full[10][len(full[10]) // 2].astype(np.float64)
    radius = 1.5
    in_sphere = lambda f: np.linalg.norm(f.astype(np.float64) - c, axis=1) <= radius  # noqa: E731
    b = full[10][0].astype(np.float64)
    blo, bhi = b - 2.0, b + 2.0
    in_box = lambda f: np.all((f >= blo.astype(np.float32)) & (f <= bhi.astype(np.float32)), axis=1)  # noqa: E731
    cases = [
        (fiblet.Sphere(c, radius), [in_sphere], []),
        (fiblet.Box(blo, bhi), [in_box], []),
        ([fiblet.Sphere(c, radius), fiblet.Box(blo, bhi)], [in_sphere, in_box], []),
        ([fiblet.Box(blo, bhi), fiblet.Sphere(c, radius, exclude=True)], [in_box], [in_sphere]),
    ]
    for roi, include, exclude in cases:
        expected = brute_force_roi(full, include, exclude)
        s = fiblet.load(fft, roi=roi)
        assert list(s.fiber_ids) == expected
        assert 0 < len(expected) < len(full), len(expected)  # the query really selects
        for mine, i in zip(s, expected):
            np.testing.assert_array_equal(mine, full[i])
    # With a subset, the ROI applies to those fibers only, ids stay the file's.
    sub = fiblet.load(fft, fibers=range(20, 60), roi=fiblet.Sphere(c, radius))
    assert list(sub.fiber_ids) == [i for i in brute_force_roi(full, [in_sphere]) if 20 <= i < 60]


def test_bad_arguments_and_bad_files(tmp_path, compressed, shared):
    fft, tck = compressed("dwi-small64d-ifod1")
    with pytest.raises(FileNotFoundError):
        fiblet.load(tmp_path / "missing.fft")
    with pytest.raises(ValueError):
        fiblet.load(fft, roi=fiblet.Sphere((0, 0), 1))
    with pytest.raises(ValueError):
        fiblet.load(fft, roi=fiblet.Box((0, 0, 0), (-1, 1, 1)))
    with pytest.raises(ValueError):
        fiblet.load(fft, threads=0)
    with pytest.raises(ValueError, match=r"\[1, 1024\]"):
        fiblet.load(fft, threads=10**6)  # the CLI's and the library's limit
    # Indices beyond int64 or unsigned near 2**64 are out of range, never wrapped to -1 (the last fiber).
    with pytest.raises(IndexError):
        fiblet.load(fft, fibers=np.array([2**64 - 1], np.uint64))
    with pytest.raises(IndexError):
        fiblet.load(fft, fibers=10**30)
    with pytest.raises(IndexError):
        fiblet.load(fft, fibers=[0, -(10**30)])
    with pytest.raises(fiblet.FibletError) as e:
        fiblet.load(tck)  # a .tck is not a .fft: named, a format fiblet knows but load does not take
    assert e.value.category == "unsupported" and "MRtrix3 .tck" in str(e.value)
    truncated = tmp_path / "truncated.fft"
    truncated.write_bytes(fft.read_bytes()[: fft.stat().st_size // 2])
    with pytest.raises(fiblet.FibletError):
        fiblet.load(truncated)


def test_threads_and_decode_paths_give_the_same_points(compressed):
    # 14,736 blocks: decoded as several runs in parallel with threads > 1.
    fft, _ = compressed("small-sdstream")
    one = fiblet.load(fft, threads=1)
    for threads in (2, 3, None):
        other = fiblet.load(fft, threads=threads)
        np.testing.assert_array_equal(one.points, other.points)
        np.testing.assert_array_equal(one.offsets, other.offsets)
    # An index list goes through the library's decode_fibers, not the
    # module's range decoder: the same points.
    listed = fiblet.load(fft, fibers=np.arange(len(one)))
    np.testing.assert_array_equal(one.points, listed.points)
    np.testing.assert_array_equal(one.offsets, listed.offsets)


def test_sixteen_bit_files_load_the_reference_decoders_points(tmp_path, shared, cli):
    # A 16-bit file (version 17, packed blocks) goes through the same range
    # decoder as an 8-bit one: its points are the scalar reference decoder's,
    # as the CLI writes them, for one thread and several.
    fft, ref = tmp_path / "wide.fft", tmp_path / "ref.tck"
    subprocess.run([cli, "compress", "-q", "--bits", "16", str(shared / "small-sdstream.tck"), "-o", str(fft)], check=True)
    subprocess.run([cli, "decompress", "-q", "--decoder", "scalar", str(fft), "-o", str(ref)], check=True)
    assert fiblet.info(fft)["block_bytes"] > 76
    reference = nib.streamlines.load(str(ref)).streamlines
    for threads in (1, 2):
        s = fiblet.load(fft, threads=threads)
        np.testing.assert_array_equal(s.points, reference.get_data())
        np.testing.assert_array_equal(s.offsets[1:] - s.offsets[:-1], reference._lengths)


def test_damaged_trailer_is_an_integrity_error_unless_ignored(tmp_path, compressed):
    fft, _ = compressed("dwi-small64d-ifod1")
    damaged = tmp_path / "damaged.fft"
    damaged.write_bytes(fft.read_bytes()[:-1])  # the footer is cut: no checksum can be found
    with pytest.raises(fiblet.FibletError) as e:
        fiblet.load(damaged)
    assert e.value.category == "checksum"
    with pytest.raises(fiblet.FibletError):
        fiblet.info(damaged)
    salvaged = fiblet.load(damaged, ignore_trailer=True)
    whole = fiblet.load(fft)
    np.testing.assert_array_equal(salvaged.points, whole.points)
    np.testing.assert_array_equal(salvaged.offsets, whole.offsets)
    assert fiblet.info(damaged, ignore_trailer=True)["properties"] == []
