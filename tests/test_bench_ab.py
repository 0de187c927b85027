"""scripts/bench_ab.sh: the before/after compress timing of two binaries
reports each side's median and whether they wrote the same bytes."""
import os
import subprocess

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
SCRIPT = os.path.join(ROOT, "scripts", "bench_ab.sh")
FIBLET = os.environ["FIBLET_CLI"]
TCK = os.path.join(ROOT, "..", "shared", "data", "small-sdstream.tck")


def run(*args):
    return subprocess.run([SCRIPT, "--tck", TCK, "--rounds", "2", *args], capture_output=True, text=True)


def test_one_binary_against_itself_writes_the_same_bytes():
    r = run("--effort", "0", FIBLET, FIBLET)
    assert r.returncode == 0, r.stderr
    line = next(l for l in r.stdout.splitlines() if l.startswith("effort 0:"))
    assert "bytes the same" in line and "new/old" in line
    assert len(r.stdout.splitlines()[2].split()) == 3  # "old:" and two rounds


def test_a_binary_writing_other_bytes_is_reported(tmp_path):
    other = tmp_path / "other-fiblet"
    other.write_text(f'#!/bin/sh\nexec "{FIBLET}" "$@" --block-points 30\n')
    other.chmod(0o755)
    r = run("--effort", "0", FIBLET, str(other))
    assert r.returncode == 0, r.stderr
    assert "bytes DIFFER" in r.stdout


def test_usage_errors_exit_2():
    assert run(FIBLET).returncode == 2
    assert run("--effort", "0", FIBLET, "/nonexistent/fiblet").returncode == 2
