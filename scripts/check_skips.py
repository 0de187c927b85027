#!/usr/bin/python3
"""Fails the test run when a test was skipped, unless its reason's category is allowed.

A skipped test has not passed: a CI machine whose EGL, MRtrix3 or ../shared
broke would otherwise stay green with part of the suite not run. Reads the
JUnit file `ctest --output-junit` wrote, sorts each skipped test by the reason
it printed (GTEST_SKIP's message, pytest's -rs line) into a category, prints
the counts, and exits 1 when a skipped test's category is not in
FIBLET_ALLOW_SKIPS (comma-separated; empty by default). Disabled tests
(DISABLED_ prefix: deliberate, named in the source) are counted, not failed.

Categories: gl (no headless OpenGL 4.5 context), shared-data (../shared/data
missing), mrtrix3, embree, nibabel (nibabel or dipy for Python), sanitizer
(measurements meaningless under ASan). Any other reason is "other" and never
allowed.

  scripts/check_skips.py build/ctest-junit.xml
  FIBLET_ALLOW_SKIPS=gl,mrtrix3 scripts/test.sh
"""
import os
import re
import sys
import xml.etree.ElementTree as ET

CATEGORIES = [
    ("gl", r"no headless OpenGL"),
    ("shared-data", r"shared (test )?data"),
    ("mrtrix3", r"MRtrix3|tckstats|tckedit|tckinfo|mrconvert|mrinfo|sh2amp"),
    ("embree", r"Embree"),
    ("nibabel", r"nibabel|dipy"),
    ("sanitizer", r"AddressSanitizer"),
]


def category(output):
    for name, pattern in CATEGORIES:
        if re.search(pattern, output):
            return name
    return "other"


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    allowed = {c for c in os.environ.get("FIBLET_ALLOW_SKIPS", "").split(",") if c}
    unknown = allowed - {name for name, _ in CATEGORIES}
    if unknown:
        sys.exit(f"check_skips: FIBLET_ALLOW_SKIPS names unknown categories: {', '.join(sorted(unknown))}")
    skipped, disabled = {}, 0
    for case in ET.parse(sys.argv[1]).getroot().iter("testcase"):
        status = case.get("status")
        if status == "disabled":
            disabled += 1
        elif status == "notrun" and case.find("skipped") is not None:
            out = case.findtext("system-out") or ""
            skipped.setdefault(category(out), []).append(case.get("name"))
    failed = False
    for name, tests in sorted(skipped.items()):
        ok = name in allowed
        failed |= not ok
        note = "allowed by FIBLET_ALLOW_SKIPS" if ok else "not allowed"
        print(f"check_skips: {len(tests)} skipped ({name}, {note}): {', '.join(tests[:5])}{' ...' if len(tests) > 5 else ''}")
    total = sum(len(t) for t in skipped.values())
    print(f"check_skips: {total} skipped, {disabled} disabled")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
