#!/usr/bin/env python3
"""bench/results.md is made of sections, each written by its own script
(bench_table.sh: the head; bench_pipeline.sh: "Parallel pipeline";
bench_front.sh: "Compress time against error"). A section is its "## "
heading and what follows up to the next "## " heading; writing one keeps
the others where they are.

  bench/results_sections.py RESULTS.md SECTION.md [SECTION.md ...]
replaces in RESULTS.md each section whose heading opens a SECTION.md (its
first "## " line), or appends it at the end.
"""
import sys


def replace_section(doc: str, section: str) -> str:
    """doc with `section` (text starting at its "## " heading) in place of the
    section of the same heading, or appended."""
    heading = next(line for line in section.splitlines() if line.startswith("## "))
    section = section.strip("\n") + "\n"
    at = doc.find(heading + "\n")
    if at < 0:
        return doc.rstrip("\n") + "\n\n" + section
    nxt = doc.find("\n## ", at + len(heading))
    return doc[:at] + section + ("\n" + doc[nxt + 1:] if nxt >= 0 else "")


if __name__ == "__main__":
    path = sys.argv[1]
    doc = open(path).read()
    for name in sys.argv[2:]:
        doc = replace_section(doc, open(name).read())
    open(path, "w").write(doc)
