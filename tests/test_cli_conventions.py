"""The CLI's conventions, checked on the built binary: --version, `fiblet
help SUBCOMMAND`, --json output that parses, and the documented exit codes
(docs/cli.md) being the ones actually returned."""
import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CLI = os.environ.get("FIBLET_CLI", str(ROOT / "build" / "bin" / "fiblet"))
SHARED = Path(os.environ.get("FIBLET_SHARED_DATA", ROOT.parent / "shared" / "data"))


def fiblet(*args):
    return subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)


def documented_exit_codes():
    text = (ROOT / "docs" / "cli.md").read_text()
    section = text.split("## Exit codes", 1)[1]
    return {int(m.group(1)): m.group(2) for m in re.finditer(r"^\| (\d+) \| (.+) \|$", section, re.M)}


def subcommands():
    out = fiblet("help").stdout
    return re.findall(r"^  (\w+)\s{2,}", out.split("Subcommands:", 1)[1], re.M)


def test_version():
    r = fiblet("--version")
    assert r.returncode == 0
    assert re.fullmatch(r"fiblet \d+\.\d+\.\d+\n", r.stdout)
    if "FIBLET_VERSION" in os.environ:
        assert r.stdout == f"fiblet {os.environ['FIBLET_VERSION']}\n"


def test_help_subcommand_equals_dash_dash_help():
    names = subcommands()
    assert {"compress", "decompress", "stats", "info", "help"} <= set(names)
    for name in names:
        via_help, via_flag = fiblet("help", name), fiblet(name, "--help")
        assert via_help.returncode == 0 and via_flag.returncode == 0
        assert f"fiblet {name}" in via_help.stdout
        # Same text, apart from the program name CLI11 takes from argv[0].
        assert via_help.stdout.split("\n", 2)[2] == via_flag.stdout.split("\n", 2)[2]
    r = fiblet("help", "no-such-command")
    assert r.returncode == 2 and "no-such-command" in r.stderr


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    if not SHARED.is_dir():
        pytest.skip(f"shared data not found at {SHARED}")
    d = tmp_path_factory.mktemp("cli")
    tck = SHARED / "dwi-small64d-ifod1.tck"
    return d, tck


def test_json_outputs_parse(files):
    d, tck = files
    fft = d / "a.fft"
    compress = json.loads(fiblet("compress", "--json", tck, "-o", fft).stdout)
    assert compress["fibers"] == 500 and compress["output"] == str(fft)
    several = fiblet("compress", "--json", "--force", "--output-dir", d, tck, SHARED / "bundles" / "AF_L.tck")
    assert [r["input"] for r in json.loads(several.stdout)] == [str(tck), str(SHARED / "bundles" / "AF_L.tck")]
    decompress = json.loads(fiblet("decompress", "--json", fft, "-o", d / "back.tck").stdout)
    assert decompress["points"] == compress["points"]
    stats = json.loads(fiblet("stats", "--json", fft, "-r", tck).stdout)
    # compress reports the header's max (per point the worse of fiblet's
    # float32 decode and an exact float64 decode); stats measures fiblet's
    # decoder against the input, which is at most that.
    assert stats["header_max_error_um"] == pytest.approx(compress["max_error_um"], rel=1e-6)
    assert stats["error"]["max_um"] <= compress["max_error_um"] * (1 + 1e-6)
    for path, fmt in ((fft, "fft"), (tck, "tck")):
        assert json.loads(fiblet("info", "--json", path).stdout)["format"] == fmt


def test_exit_codes_are_the_documented_ones(files):
    d, tck = files
    documented = documented_exit_codes()
    assert documented[0] == "success"
    fft = d / "codes.fft"
    assert fiblet("compress", tck, "-o", fft).returncode == 0
    cases = {
        "usage": (fiblet("compress", "--step", "not-a-number", tck), 2),
        "missing input": (fiblet("info", d / "missing.fft"), 2),
        "exists": (fiblet("compress", tck, "-o", fft), 5),
        "bad input": (fiblet("info", SHARED / "conformance" / "no_magic_number.tck"), 4),
        "mismatched reference": (fiblet("stats", fft, "-r", SHARED / "bundles" / "AF_L.tck"), 4),
    }
    for label, (result, code) in cases.items():
        assert result.returncode == code, (label, result.stderr)
        assert code in documented, label
        assert result.stdout == "" or code == 2, label  # errors go to stderr
    # An error above --max-error: the report on stdout, the reason on stderr, code 8.
    above = fiblet("stats", fft, "-r", tck, "--max-error", "0.001")
    assert above.returncode == 8 and 8 in documented
    assert "Hausdorff" in above.stdout and "above --max-error" in above.stderr
    # A file that is neither .tck nor .fft, given as .fft: bad input too.
    bogus = d / "bogus.fft"
    bogus.write_bytes(b"\x02" + b"\x00" * 100)
    assert fiblet("info", bogus).returncode == 4
