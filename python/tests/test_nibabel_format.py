"""nibabel opens .fft/.fftz through fiblet (fiblet/nibabel_format.py):
detect_format, load and save through nibabel's own API, compared with
fiblet.load and with the source .trk as nibabel reads it."""
import os
import subprocess
import sys

import numpy as np
import pytest

import fiblet

nib = pytest.importorskip("nibabel")
from fiblet.nibabel_format import FftFile  # noqa: E402


def max_distance(a, b):
    assert len(a) == len(b)
    return max(float(np.linalg.norm(np.asarray(x, np.float64) - np.asarray(y, np.float64), axis=1).max())
               for x, y in zip(a, b) if len(x))


def assert_same_data(tractogram, reference):
    """data_per_streamline and data_per_point equal (names, values, dtype kinds)."""
    assert set(tractogram.data_per_streamline.keys()) == set(reference.data_per_streamline.keys())
    assert set(tractogram.data_per_point.keys()) == set(reference.data_per_point.keys())
    for k in reference.data_per_streamline.keys():
        np.testing.assert_array_equal(tractogram.data_per_streamline[k], reference.data_per_streamline[k])
    for k in reference.data_per_point.keys():
        got, want = tractogram.data_per_point[k], reference.data_per_point[k]
        assert len(got) == len(want)
        np.testing.assert_array_equal(got.get_data(), want.get_data())
        np.testing.assert_array_equal(got[1], want[1])  # per fiber, not only flat


def test_detect_format_by_content_and_extension(shared, tmp_path):
    trk = shared / "conformance" / "complex.trk"
    fft = tmp_path / "c.fft"
    fiblet.save(fft, str(trk))
    assert nib.streamlines.detect_format(str(fft)) is FftFile
    assert nib.streamlines.detect_format(str(tmp_path / "new.fft")) is FftFile    # to be written: by name
    assert nib.streamlines.detect_format(str(tmp_path / "new.FFTZ")) is FftFile
    renamed = tmp_path / "c.bin"                                                 # by content, whatever its name
    renamed.write_bytes(fft.read_bytes())
    assert nib.streamlines.detect_format(str(renamed)) is FftFile
    assert nib.streamlines.detect_format(str(trk)) is nib.streamlines.TrkFile   # others unchanged
    assert not FftFile.is_correct_format(str(trk))


def test_load_gives_fiblet_points_and_the_trk_data(shared, tmp_path):
    trk = shared / "conformance" / "complex.trk"
    fft = tmp_path / "c.fft"
    fiblet.save(fft, str(trk))
    f = nib.streamlines.load(str(fft))
    assert isinstance(f, FftFile)
    np.testing.assert_array_equal(f.tractogram.affine_to_rasmm, np.eye(4))
    s, data = fiblet.load(fft, data=True)
    np.testing.assert_array_equal(f.streamlines.get_data(), s.points)
    np.testing.assert_array_equal(f.streamlines._lengths, s.lengths)
    for name, values in data.items():
        scope, short = name.split("/", 1)
        got = f.tractogram.data_per_streamline[short] if scope == "dps" else f.tractogram.data_per_point[short].get_data()
        np.testing.assert_array_equal(got, values)
    source = nib.streamlines.load(str(trk))
    assert_same_data(f.tractogram, source.tractogram)
    assert max_distance(f.streamlines, source.streamlines) <= fiblet.info(fft)["max_error_um"] / 1000 + 1e-6


@pytest.mark.parametrize("ext", [".fft", ".fftz"])
def test_save_compresses_with_the_data(shared, tmp_path, ext):
    trk = shared / "conformance" / "complex.trk"
    source = nib.streamlines.load(str(trk))
    out = tmp_path / ("c" + ext)
    nib.streamlines.save(source.tractogram, str(out))
    assert fiblet.info(out)["fibers"] == len(source.streamlines)
    s, data = fiblet.load(out, data=True)
    assert max_distance(s, source.streamlines) <= fiblet.info(out)["max_error_um"] / 1000 + 1e-5
    back = nib.streamlines.load(str(out))
    assert_same_data(back.tractogram, source.tractogram)
    # Saved again over it (nibabel's formats replace), and through the file object's own save.
    FftFile(back.tractogram).save(str(out))
    assert_same_data(nib.streamlines.load(str(out)).tractogram, source.tractogram)


def test_save_points_only_and_refusals(tmp_path):
    t = np.linspace(0, 1, 60)[:, None]
    fibers = [np.hstack([10 * t, 2 * t + k, np.zeros_like(t)]).astype(np.float32) for k in range(5)]
    out = tmp_path / "p.fft"
    nib.streamlines.save(nib.streamlines.Tractogram(fibers, affine_to_rasmm=np.eye(4)), str(out))
    s = fiblet.load(out)
    assert max_distance(s, fibers) <= fiblet.info(out)["max_error_um"] / 1000 + 1e-6
    loaded = nib.streamlines.load(str(out))
    assert len(loaded.tractogram.data_per_streamline) == 0 and len(loaded.tractogram.data_per_point) == 0
    with pytest.raises(ValueError, match=r"\.fft or \.fftz"):
        FftFile(loaded.tractogram).save(str(tmp_path / "p.trk"))
    with open(out, "rb") as fileobj:
        assert not FftFile.is_correct_format(fileobj)
        with pytest.raises(TypeError, match="by path"):
            FftFile.load(fileobj)


def test_fiblet_imports_without_nibabel(shared, tmp_path):
    fft = tmp_path / "c.fft"
    fiblet.save(fft, str(shared / "conformance" / "complex.trk"))
    code = ("import sys; sys.modules['nibabel'] = None\n"  # any import of nibabel fails
            "import fiblet\n"
            f"s = fiblet.load({str(fft)!r}); print(len(s))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == str(len(fiblet.load(fft)))
