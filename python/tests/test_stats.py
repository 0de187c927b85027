"""fiblet.stats and fiblet.info against the CLI's JSON for the same files."""
import json
import subprocess

import numpy as np
import pytest

import fiblet

nib = pytest.importorskip("nibabel")


def test_stats_equal_cli_and_brute_force(compressed, cli):
    fft, tck = compressed("dwi-small64d-ifod1")
    mine = fiblet.stats(fft, tck)
    theirs = json.loads(subprocess.run([cli, "stats", "--json", str(fft), "-r", str(tck)], check=True,
                                       capture_output=True, text=True).stdout)
    assert set(mine) == set(theirs)
    for key in ("fibers", "points", "blocks", "fft_bytes", "reference_bytes"):
        assert mine[key] == theirs[key]
    for key in ("max_um", "mean_um", "rms_um", "p99_um"):
        assert mine["error"][key] == pytest.approx(theirs["error"][key], rel=1e-6)
    # The same numbers from the points themselves (nibabel reads the reference).
    s = fiblet.load(fft)
    ref = nib.streamlines.load(str(tck)).streamlines.get_data()
    dist = np.linalg.norm(s.points.astype(np.float64) - ref, axis=1) * 1e3
    assert mine["error"]["max_um"] == pytest.approx(dist.max(), rel=1e-4)
    assert mine["error"]["mean_um"] == pytest.approx(dist.mean(), rel=1e-4)
    assert mine["error"]["max_um"] <= mine["header_max_error_um"] * (1 + 1e-4) + 1e-4


def test_info_equals_cli(compressed, cli):
    fft, _ = compressed("dwi-small64d-ifod1")
    mine = fiblet.info(fft)
    theirs = json.loads(subprocess.run([cli, "info", "--json", str(fft)], check=True, capture_output=True,
                                       text=True).stdout)
    for key in ("fibers", "points", "blocks", "points_per_block", "block_bytes"):
        assert mine[key] == theirs[key]
    # One name for one thing: the direction code's cap ratio is "cap_ratio" in both.
    for key in ("step_mm", "max_error_um", "mean_error_um", "cap_ratio"):
        assert mine[key] == pytest.approx(theirs[key], rel=1e-6)
    assert [list(p) for p in mine["properties"]] == theirs["properties"]


def test_stats_refuses_a_mismatched_reference(compressed, shared):
    fft, _ = compressed("dwi-small64d-ifod1")
    with pytest.raises(fiblet.FibletError) as e:
        fiblet.stats(fft, shared / "small-sdstream.tck")
    assert e.value.category == "invalid_input"


def test_geometry_metrics_equal_cli_and_the_points(compressed, cli):
    # A resampled file (6 mm input spacing): ends kept, metrics both ways.
    fft, tck = compressed("bundles/AF_L")
    mine = fiblet.stats(fft, tck)["geometry"]
    theirs = json.loads(subprocess.run([cli, "stats", "--json", str(fft), "-r", str(tck)], check=True,
                                       capture_output=True, text=True).stdout)["geometry"]
    assert set(mine) == set(theirs)
    assert mine["hausdorff_um"] == pytest.approx(theirs["hausdorff_um"], rel=1e-8)
    for key in ("decoded_to_input", "input_to_decoded", "endpoint", "length_change"):
        for k, v in theirs[key].items():
            assert mine[key][k] == pytest.approx(v, rel=1e-8, abs=1e-9), (key, k)
    # Endpoint displacement and length change from the points themselves.
    s = fiblet.load(fft)
    ref = nib.streamlines.load(str(tck)).streamlines
    ends, lengths = [], []
    for i, r in enumerate(ref):
        d = s.points[s.offsets[i]:s.offsets[i + 1]].astype(np.float64)
        r = np.asarray(r, dtype=np.float64)
        ends += [np.linalg.norm(d[0] - r[0]), np.linalg.norm(d[-1] - r[-1])]
        length = lambda p: np.linalg.norm(np.diff(p, axis=0), axis=1).sum()
        lengths.append(abs(length(d) - length(r)))
    assert mine["endpoint"]["max_um"] == pytest.approx(max(ends) * 1e3, rel=1e-4)
    assert mine["endpoint"]["mean_um"] == pytest.approx(np.mean(ends) * 1e3, rel=1e-4)
    assert mine["length_change"]["max_um"] == pytest.approx(max(lengths) * 1e3, rel=1e-4)
    # The ends stay within the error the encoder recorded (the dropped tail moved them by up to 6.6 mm).
    assert mine["endpoint"]["max_um"] <= fiblet.info(fft)["max_error_um"] * (1 + 1e-5)
