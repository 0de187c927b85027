#!/usr/bin/env bash
# The test command: installs dependencies, builds, runs the whole suite with CTest.
#   scripts/test.sh              Release build in build/
#   FIBLET_SANITIZE=ON scripts/test.sh   ASan+UBSan build in build-sanitize/
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
ctest --output-on-failure -j"$(nproc)"
