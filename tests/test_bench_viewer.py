"""scripts/bench_viewer.sh --quick on this machine's renderer (llvmpipe in
CI): every technique is measured and tabled, and the build carried by
--bundle runs on its own libraries. Environment: FIBLET_CLI, FIBLET_ODF
(an SH image for the glyph case)."""
import json
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "scripts" / "bench_viewer.sh"
TECHNIQUES = 12  # bench_viewer.sh's cases, the glyphs included


def run(args, **kw):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=600, **kw)


@pytest.fixture(scope="module")
def cli():
    cli = os.environ["FIBLET_CLI"]
    probe = run([cli, "render", ROOT.parent / "shared/data/bundles/CST_R.tck", "--size", "8x8", "--bench",
                 "--bench-views", "far", "--frames", "1"])
    if probe.returncode == 6:
        pytest.skip("no headless OpenGL 4.5 context: " + probe.stderr.strip())
    assert probe.returncode == 0, probe.stderr
    return cli


def check_results(out, techniques):
    doc = json.loads((out / "results-viewer.json").read_text())
    rows = doc["rows"]
    assert [r["technique"] for r in rows][:3] == ["lines", "tubes", "capsules"]
    assert len(rows) == techniques
    for row in rows:
        result = row["result"]
        assert result["device"], row["technique"]
        cases = {(c["view"], c["culling_and_lod"]): c for c in result["cases"]}
        assert set(cases) == {(v, s) for v in ("overview", "close-up") for s in (True, False)}, row["technique"]
        for c in cases.values():
            assert c["frame_ms"] > 0, row["technique"]
    # The full decodes are timed once, with the first case.
    assert rows[0]["result"]["decode_all_scan_ms"] > 0
    assert all(r["result"]["decode_all_scan_ms"] is None for r in rows[1:])
    table = (out / "results-viewer.md").read_text()
    assert rows[0]["result"]["device"] in table
    assert sum(line.startswith("| ") for line in table.splitlines()) == techniques + 1  # the header row too
    return rows


def test_quick_run_measures_every_technique(cli, tmp_path):
    odf = os.environ["FIBLET_ODF"]
    r = run([SCRIPT, "--quick", "--fiblet", cli, "--out", tmp_path, "--odf", odf])
    assert r.returncode == 0, r.stderr
    rows = check_results(tmp_path, TECHNIQUES)
    assert "--odf" in rows[-1]["options"]
    engines = {row["technique"]: row["result"]["engine"] for row in rows}
    assert engines["voxel-rt, AO + shadows"] == "voxel-rt" and engines["tubes"] == "raster"


def test_bundle_runs_on_its_own_libraries(cli, tmp_path):
    bundle = tmp_path / "bundle"
    r = run([SCRIPT, "--bundle", bundle, "--fiblet", cli])
    assert r.returncode == 0, r.stderr
    libs = sorted(p.name for p in (bundle / "lib").iterdir())
    assert libs, "no library carried"
    assert not any(n.startswith(("libc.so", "libGL", "libEGL")) for n in libs)
    # Every carried library resolves from the bundle.
    env = dict(os.environ, LD_LIBRARY_PATH=str(bundle / "lib"))
    ldd = run(["ldd", bundle / "fiblet"], env=env).stdout
    for name in libs:
        line = next(line for line in ldd.splitlines() if line.strip().startswith(name))
        assert str(bundle / "lib") in line, line
    fft = tmp_path / "cst.fft"
    assert run([cli, "compress", "-q", ROOT.parent / "shared/data/bundles/CST_R.tck", "-o", fft]).returncode == 0
    out = tmp_path / "results"
    r = run([bundle / "run.sh", "--quick", "--input", fft], env=dict(os.environ, OUT=str(out)))
    assert r.returncode == 0, r.stderr
    assert "glyphs not measured" in r.stderr  # no --odf given, none beside the bundle
    check_results(out, TECHNIQUES - 1)
