"""The cohort Snakefile, unchanged, on a real scheduler: a single-node SLURM
on localhost (local_slurm.py) runs its compress and stats jobs through
Snakemake's cluster support (`--cluster sbatch ...`), and the summary must
equal the one a local run gives."""
import csv
import os
import shutil
import tempfile
from pathlib import Path

import pytest

import local_slurm
from test_workflow import COHORT, SNAKEMAKE, cohort, run_workflow  # noqa: F401 (cohort is a fixture)

# Where the cluster's key, configuration, state and logs go (CMake: the build tree).
SLURM_ROOT = Path(os.environ.get("FIBLET_SLURM_DIR", tempfile.gettempdir()))
# Well under CTest's TIMEOUT, so the test stops the cluster itself.
WORKFLOW_TIMEOUT_S = 180


def summary_rows(out):
    with open(out / "summary.csv") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        del r["compress_seconds"]  # the only column that is not a property of the data
    return rows


def test_cohort_on_slurm(cohort, tmp_path_factory):
    missing = local_slurm.missing_programs()
    if missing:
        pytest.fail(f"{', '.join(missing)} not found (scripts/setup.sh installs Debian's slurm-wlm and munge)")
    local_out, slurm_out = tmp_path_factory.mktemp("local"), tmp_path_factory.mktemp("slurm")
    run_workflow(cohort, f"output_dir={local_out}", timeout=WORKFLOW_TIMEOUT_S)

    # The munge socket's path must fit a sockaddr_un (108 bytes): a deep build tree falls back to $TMPDIR.
    root = SLURM_ROOT if len(str(SLURM_ROOT)) < 70 else Path(tempfile.gettempdir())
    root.mkdir(parents=True, exist_ok=True)
    cluster_dir = Path(tempfile.mkdtemp(prefix="slurm-", dir=root))
    logs = cluster_dir / "jobs"
    logs.mkdir()
    sbatch = (f"sbatch --parsable --job-name={{rule}} --cpus-per-task={{threads}} --mem={{resources.mem_mb}} "
              f"--output={logs}/%x-%j.out")
    with local_slurm.LocalSlurm(cluster_dir) as env:
        run = run_workflow(cohort, f"output_dir={slurm_out}", "--cluster", sbatch, "--cluster-cancel", "scancel",
                           "--latency-wait", "30", env=env, timeout=WORKFLOW_TIMEOUT_S)

    # Every compress and stats job ran as a SLURM job (its log names its
    # rule); all, summary are local rules.
    job_logs = sorted(p.name.split("-")[0] for p in logs.iterdir())
    assert job_logs == ["compress"] * len(COHORT) + ["stats"] * len(COHORT), run.stderr
    assert run.stderr.count("with external jobid") == 2 * len(COHORT)

    assert summary_rows(slurm_out) == summary_rows(local_out)
    for same in ("summary.md", "dataset_description.json"):
        assert (slurm_out / same).read_text() == (local_out / same).read_text(), same
    for name in COHORT:
        fft = name.replace(".tck", ".fft")
        assert (slurm_out / fft).read_bytes() == (local_out / fft).read_bytes(), fft
    shutil.rmtree(cluster_dir)  # kept when the test fails, for the daemons' and jobs' logs
