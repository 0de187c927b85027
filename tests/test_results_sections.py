"""bench/results_sections.py: each script's section of bench/results.md is
replaced in place, the others kept (a pipeline run once dropped the
time-error section that followed its own)."""
import os
import subprocess
import sys

BENCH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "bench")
sys.path.insert(0, BENCH)
from results_sections import replace_section  # noqa: E402

DOC = "# Results\n\nhead\n\n## Parallel pipeline\nold pipeline\n\n## Compress time against error\nold front\n"


def test_a_middle_section_keeps_the_ones_after_it():
    out = replace_section(DOC, "## Parallel pipeline\nnew pipeline\n")
    assert out == "# Results\n\nhead\n\n## Parallel pipeline\nnew pipeline\n\n## Compress time against error\nold front\n"


def test_the_last_section_and_a_new_one():
    out = replace_section(DOC, "## Compress time against error\nnew front\n")
    assert out.endswith("## Parallel pipeline\nold pipeline\n\n## Compress time against error\nnew front\n")
    assert replace_section(DOC, "## Other\nx\n").endswith("old front\n\n## Other\nx\n")


def test_the_command_replaces_each_file_given(tmp_path):
    doc, a, b = tmp_path / "results.md", tmp_path / "a.md", tmp_path / "b.md"
    doc.write_text(DOC)
    a.write_text("## Compress time against error\nfront 2\n")
    b.write_text("## Parallel pipeline\npipeline 2\n")
    subprocess.run([sys.executable, os.path.join(BENCH, "results_sections.py"), str(doc), str(a), str(b)], check=True)
    text = doc.read_text()
    assert "pipeline 2" in text and "front 2" in text and "old" not in text
    assert text.index("pipeline 2") < text.index("front 2")
