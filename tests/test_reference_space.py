"""`--reference IMAGE` (compress, decompress): a .tck source gets the space
of a NIfTI image, as tckconvert's and DIPY's reference give it, checked
through nibabel (the image's affine and shape, the .trk it reads back) and
the TRX spec (header.json). Environment: FIBLET_CLI, FIBLET_SHARED_DATA."""
import json
import os
import pathlib
import subprocess
import zipfile

import numpy as np
import pytest

nib = pytest.importorskip("nibabel", reason="needs nibabel (Debian: python3-nibabel)")

CLI = os.environ["FIBLET_CLI"]
TCK = pathlib.Path(os.environ["FIBLET_SHARED_DATA"]) / "bundles" / "CST_R.tck"
# An oblique, anisotropic, LPS-ish grid around the bundle.
AFFINE = np.array([[-1.25, 0.1, 0.0, 80.0], [0.0, -1.1, 0.2, 90.0], [0.05, 0.0, 1.5, -60.0], [0, 0, 0, 1]])
SHAPE = (128, 150, 96)


def fiblet(*args):
    return subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, timeout=300)


@pytest.fixture()
def reference(tmp_path):
    path = tmp_path / "ref.nii.gz"
    nib.save(nib.Nifti1Image(np.zeros(SHAPE, np.uint8), AFFINE), str(path))
    return path


def trx_header(path):
    with zipfile.ZipFile(path) as z:
        return json.loads(z.read("header.json"))


def check_space(trx, trk):
    header = trx_header(trx)
    np.testing.assert_allclose(np.array(header["VOXEL_TO_RASMM"]), AFFINE, atol=1e-5)
    assert header["DIMENSIONS"] == list(SHAPE)
    t = nib.streamlines.load(str(trk))
    np.testing.assert_allclose(t.header["voxel_to_rasmm"], AFFINE, atol=1e-4)
    assert tuple(int(d) for d in t.header["dimensions"]) == SHAPE
    # Points stay in world millimetres: the .trk read back by nibabel is the .tck.
    source = nib.streamlines.load(str(TCK)).streamlines
    assert len(t.streamlines) == len(source)
    assert np.abs(t.streamlines[0][0] - source[0][0]).max() < 0.05


def test_decompress_reference_gives_trx_and_trk_the_image_space(tmp_path, reference):
    fft = tmp_path / "cst.fft"
    assert fiblet("compress", "-q", TCK, "-o", fft).returncode == 0
    for out in ("cst.trx", "cst.trk"):
        r = fiblet("decompress", fft, "--reference", reference, "-o", tmp_path / out)
        assert r.returncode == 0, r.stderr
        assert "carries no space" not in r.stderr
    check_space(tmp_path / "cst.trx", tmp_path / "cst.trk")
    # Without one, the identity space is written and said to be so.
    r = fiblet("decompress", fft, "-o", tmp_path / "bare.trx")
    assert r.returncode == 0, r.stderr
    assert "carries no space" in r.stderr and "--reference IMAGE" in r.stderr
    assert trx_header(tmp_path / "bare.trx")["DIMENSIONS"] == [1, 1, 1]


def test_compress_reference_is_stored_and_travels(tmp_path, reference):
    fft = tmp_path / "cst.fft"
    r = fiblet("compress", "-q", TCK, "--reference", reference, "-o", fft)
    assert r.returncode == 0, r.stderr
    for out in ("cst.trx", "cst.trk"):
        r = fiblet("decompress", fft, "-o", tmp_path / out)
        assert r.returncode == 0, r.stderr
        assert "carries no space" not in r.stderr
    check_space(tmp_path / "cst.trx", tmp_path / "cst.trk")
    # A file with a space refuses another reference, and so does a .trk source.
    r = fiblet("decompress", fft, "--reference", reference, "-o", tmp_path / "again.trx")
    assert r.returncode == 2 and "carries its own space" in r.stderr
    assert not (tmp_path / "again.trx").exists()
    r = fiblet("compress", "-q", tmp_path / "cst.trk", "--reference", reference, "-o", tmp_path / "trk.fft")
    assert r.returncode == 2 and "carries its own space" in r.stderr
    assert not (tmp_path / "trk.fft").exists()
