"""Runs the cohort Snakefile on a small generated cohort (3 subjects, 4
tractograms from the shared data, symlinked into a temporary BIDS-like tree)
and checks the summary against the files themselves."""
import csv
import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
SHARED = Path(os.environ.get("FIBLET_SHARED_DATA", HERE.parents[2] / "shared" / "data"))
CLI = os.environ.get("FIBLET_CLI", "fiblet")
SNAKEMAKE = shutil.which("snakemake")

# subject/file -> shared file; sub-02's and sub-03's have variable spacing
# at the ends (resampled by the encoder).
COHORT = {
    "sub-01/dwi/sub-01_desc-ifod1_tracks.tck": "dwi-small64d-ifod1.tck",
    "sub-02/dwi/sub-02_desc-cst_tracks.tck": "bundles/CST_R-step0.1.tck",
    "sub-03/dwi/sub-03_desc-af_tracks.tck": "bundles/AF_L-step0.1.tck",
    "sub-03/dwi/sub-03_desc-cingulum_tracks.tck": "bundles/cingulum-1-step0.1.tck",
}


def tck_count(path):
    """Streamlines in a .tck, counted from its data (NaN separators), not its header."""
    import numpy as np

    with open(path, "rb") as f:
        header = f.read(4096).decode("latin-1")
    offset = int(header.split("file: . ")[1].split()[0])
    data = np.fromfile(path, dtype="<f4", offset=offset).reshape(-1, 3)
    return int(np.isnan(data[:, 0]).sum())


@pytest.fixture
def cohort(tmp_path):
    if not SHARED.is_dir():
        pytest.skip(f"shared data not found at {SHARED}")
    if SNAKEMAKE is None:
        pytest.fail("snakemake not found (scripts/setup.sh installs Debian's snakemake)")
    for name, source in COHORT.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).symlink_to(SHARED / source)
    (tmp_path / "participants.tsv").write_text("participant_id\nsub-01\nsub-02\nsub-03\n")
    return tmp_path


def run_workflow(root, *extra):
    return subprocess.run([SNAKEMAKE, "-s", str(HERE / "Snakefile"), "-j", "2", "--directory", str(root),
                           "--config", f"input_dir={root}", f"fiblet={CLI}", *extra],
                          check=True, capture_output=True, text=True)


def test_cohort_summary(cohort):
    run_workflow(cohort)
    out = cohort / "derivatives" / "fiblet"
    with open(out / "summary.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["file"] for r in rows] == sorted(COHORT)
    assert [r["subject"] for r in rows] == ["sub-01", "sub-02", "sub-03", "sub-03"]
    for r in rows:
        tck, fft = cohort / r["file"], out / r["file"].replace(".tck", ".fft")
        assert int(r["fibers"]) == tck_count(tck)
        assert int(r["tck_bytes"]) == tck.stat().st_size and int(r["fft_bytes"]) == fft.stat().st_size
        assert float(r["ratio"]) == pytest.approx(tck.stat().st_size / fft.stat().st_size, rel=1e-3)
        # The measured error is real and within what the encoder recorded.
        assert 0 < float(r["max_error_um"]) <= float(r["recorded_max_error_um"]) + 0.01
        # Endpoints stay where the input has them (resampled files included),
        # within the recorded error; the symmetric distances are real.
        assert float(r["endpoint_max_um"]) <= float(r["recorded_max_error_um"]) + 0.01
        assert 0 < float(r["input_to_decoded_mean_um"]) <= float(r["hausdorff_um"])
        stats = json.loads((out / r["file"].replace(".tck", ".stats.json")).read_text())
        assert stats["file"] == str(fft) and stats["reference"] == str(tck)
        assert float(r["hausdorff_um"]) == pytest.approx(stats["geometry"]["hausdorff_um"], abs=1e-3)
        info = json.loads(subprocess.run([CLI, "info", "--json", str(fft)], check=True, capture_output=True,
                                         text=True).stdout)
        assert int(r["points"]) == info["points"]
    assert {r["file"]: r["resampled"] for r in rows}["sub-01/dwi/sub-01_desc-ifod1_tracks.tck"] == "False"
    assert {r["file"]: r["resampled"] for r in rows}["sub-02/dwi/sub-02_desc-cst_tracks.tck"] == "True"
    md = (out / "summary.md").read_text()
    assert "4 files from 3 subjects" in md
    assert all(f"| {r['subject']} | {r['file']} | {r['fibers']} |" in md for r in rows)

    # Everything is up to date: a second run has nothing to do.
    again = run_workflow(cohort, "--dry-run", "--quiet")
    assert "compress" not in again.stdout and "stats" not in again.stdout


def test_glob_and_output_dir(cohort, tmp_path_factory):
    # A dry run shows the jobs a glob selects, without the time of running them.
    out = tmp_path_factory.mktemp("out")
    plan = run_workflow(cohort, "pattern=sub-03/**/*cingulum*.tck", f"output_dir={out}", "--dry-run",
                        "--printshellcmds").stdout
    selected = "sub-03/dwi/sub-03_desc-cingulum_tracks"
    assert f"{cohort}/{selected}.tck -o {out}/{selected}.fft" in plan
    assert plan.count(" compress --json") == 1 and plan.count(" stats --json") == 1
    assert not (cohort / "derivatives").exists()


def test_no_input_is_an_error(tmp_path):
    if SNAKEMAKE is None:
        pytest.fail("snakemake not found")
    with pytest.raises(subprocess.CalledProcessError) as e:
        run_workflow(tmp_path)
    assert "no .tck, .trk or .trx file matches" in e.value.stderr + e.value.stdout


def test_trk_and_trx_inputs(tmp_path):
    """A .trk (nibabel's TrackVis file) and a TRX made from it by fiblet are
    picked up next to a .tck; each row's size is its own source file's."""
    if SNAKEMAKE is None:
        pytest.fail("snakemake not found")
    if not SHARED.is_dir():
        pytest.skip(f"shared data not found at {SHARED}")
    dwi = tmp_path / "sub-01" / "dwi"
    dwi.mkdir(parents=True)
    (dwi / "sub-01_desc-cst_tracks.trk").symlink_to(SHARED / "bundles/CST_R.trk")
    (dwi / "sub-01_desc-simple_tracks.tck").symlink_to(SHARED / "conformance/simple.tck")
    work = tmp_path.parent / (tmp_path.name + "-work")
    work.mkdir()
    subprocess.run([CLI, "compress", "-q", str(SHARED / "conformance/complex.trk"), "-o", str(work / "c.fft")], check=True)
    subprocess.run([CLI, "decompress", "-q", str(work / "c.fft"), "-o", str(dwi / "sub-01_desc-complex_tracks.trx")],
                   check=True)
    run_workflow(tmp_path)
    out = tmp_path / "derivatives" / "fiblet"
    with open(out / "summary.csv") as f:
        rows = {r["file"]: r for r in csv.DictReader(f)}
    assert set(rows) == {"sub-01/dwi/sub-01_desc-cst_tracks.trk", "sub-01/dwi/sub-01_desc-simple_tracks.tck",
                         "sub-01/dwi/sub-01_desc-complex_tracks.trx"}
    for name, r in rows.items():
        assert int(r["tck_bytes"]) == (tmp_path / name).stat().st_size
        assert (out / name).with_suffix(".fft").is_file()
    assert rows["sub-01/dwi/sub-01_desc-cst_tracks.trk"]["fibers"] == "50"
    assert rows["sub-01/dwi/sub-01_desc-complex_tracks.trx"]["fibers"] == "3"
