"""scripts/check_skips.py: a skipped test fails the run unless its category is allowed."""
import os
import subprocess
import sys

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scripts", "check_skips.py")


def junit(tmp_path, cases):
    body = "".join(
        f'<testcase name="{name}" status="{status}">'
        + ('<skipped message="SKIP_REGULAR_EXPRESSION_MATCHED"/>' if status == "notrun" else "")
        + f"<system-out>{out}</system-out></testcase>"
        for name, status, out in cases)
    path = tmp_path / "junit.xml"
    path.write_text(f'<?xml version="1.0"?><testsuite>{body}</testsuite>')
    return str(path)


def run(path, allow=None):
    env = dict(os.environ)
    env.pop("FIBLET_ALLOW_SKIPS", None)
    if allow is not None:
        env["FIBLET_ALLOW_SKIPS"] = allow
    return subprocess.run([sys.executable, SCRIPT, path], capture_output=True, text=True, env=env)


CASES = [
    ("Viewer.A", "notrun", "x.cpp:3: Skipped\nno headless OpenGL 4.5 context: no EGL\n[  SKIPPED ] Viewer.A"),
    ("Codec.B", "notrun", "x.cpp:9: Skipped\nno shared data\n[  SKIPPED ] Codec.B"),
    ("python.test_load", "notrun", "SKIPPED [1] t.py:8: could not import 'nibabel'\n1 skipped in 0.1s"),
    ("Ok.C", "run", "[       OK ] Ok.C"),
    ("Table.D", "disabled", ""),
]


def test_every_skip_fails_by_default_and_is_counted_by_reason(tmp_path):
    r = run(junit(tmp_path, CASES))
    assert r.returncode == 1
    assert "1 skipped (gl, not allowed): Viewer.A" in r.stdout
    assert "1 skipped (shared-data, not allowed): Codec.B" in r.stdout
    assert "1 skipped (nibabel, not allowed): python.test_load" in r.stdout
    assert "3 skipped, 1 disabled" in r.stdout


def test_allowed_categories_pass_and_others_still_fail(tmp_path):
    path = junit(tmp_path, CASES)
    assert run(path, "gl,shared-data,nibabel").returncode == 0
    r = run(path, "gl,shared-data")
    assert r.returncode == 1 and "(nibabel, not allowed)" in r.stdout


def test_an_unknown_reason_is_never_allowed(tmp_path):
    path = junit(tmp_path, [("X.Y", "notrun", "[  SKIPPED ] X.Y")])
    r = run(path, "gl,shared-data,mrtrix3,embree,nibabel,sanitizer")
    assert r.returncode == 1 and "(other, not allowed)" in r.stdout


def test_a_clean_run_passes_and_an_unknown_category_is_refused(tmp_path):
    path = junit(tmp_path, [("Ok.C", "run", "")])
    assert run(path).returncode == 0
    r = run(path, "gpu")
    assert r.returncode == 1 and "unknown categories: gpu" in r.stderr
