#!/usr/bin/env bash
# The test command: installs dependencies, builds, runs the whole suite with CTest
# and fails when a test was skipped (FIBLET_ALLOW_SKIPS=gl,shared-data,mrtrix3,
# embree,nibabel allows those categories: scripts/check_skips.py).
#   scripts/test.sh              Release build in build/
#   FIBLET_SANITIZE=ON scripts/test.sh   ASan+UBSan build in build-sanitize/
# Then, when clang is installed (scripts/setup.sh installs it), each libFuzzer
# harness runs briefly: FIBLET_FUZZ_SECONDS per harness (default 20; 0 skips).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
if [ "${FIBLET_SANITIZE:-OFF}" = "ON" ]; then
  export FIBLET_BUILD_DIR="${FIBLET_BUILD_DIR:-$root/build-sanitize}"
  "$root/scripts/build.sh" -DFIBLET_SANITIZE=ON -DFIBLET_BUILD_BENCH=OFF
else
  "$root/scripts/build.sh"
fi
build="${FIBLET_BUILD_DIR:-$root/build}"
cd "$build"
ctest --output-on-failure -j"$(nproc)" --output-junit ctest-junit.xml
# A skipped test fails the run unless FIBLET_ALLOW_SKIPS names its category
# (scripts/check_skips.py); ASan builds skip their RSS measurements.
[ "${FIBLET_SANITIZE:-OFF}" != "ON" ] || export FIBLET_ALLOW_SKIPS="${FIBLET_ALLOW_SKIPS:+$FIBLET_ALLOW_SKIPS,}sanitizer"
/usr/bin/python3 "$root/scripts/check_skips.py" ctest-junit.xml
if [ "${FIBLET_SANITIZE:-OFF}" != "ON" ] && [ "${FIBLET_FUZZ_SECONDS:-20}" != "0" ]; then
  if command -v clang++-14 >/dev/null || command -v clang++ >/dev/null; then
    "$root/scripts/fuzz.sh" "${FIBLET_FUZZ_SECONDS:-20}"
  else
    echo "test.sh: clang not found: fuzzers skipped" >&2
  fi
fi
