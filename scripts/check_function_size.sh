#!/usr/bin/env bash
# No library function over 80 lines without a reason written beside it:
# clang-tidy's readability-function-size (LineThreshold 80) over the
# library's sources and their headers; a function kept longer carries
# NOLINTNEXTLINE(readability-function-size) under a comment saying why.
#   scripts/check_function_size.sh [BUILD_DIR]   (CTest layers.function_size)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-${FIBLET_BUILD_DIR:-$root/build}}"
tidy="$(command -v clang-tidy-14 || command -v clang-tidy || true)"
[ -n "$tidy" ] || { echo "check_function_size: clang-tidy not found (scripts/setup.sh installs it)" >&2; exit 1; }
[ -f "$build/compile_commands.json" ] || { echo "check_function_size: no $build/compile_commands.json" >&2; exit 1; }
config='{Checks: "-*,readability-function-size", CheckOptions: [{key: readability-function-size.LineThreshold, value: 80}]}'
found="$(find "$root/libfiblet/src" -name '*.cpp' -print0 |
  xargs -0 -P "$(nproc)" -n 8 "$tidy" -p "$build" --quiet --config="$config" --header-filter="$root/libfiblet/" 2>/dev/null |
  grep 'warning: function' | sort -u || true)"
if [ -n "$found" ]; then
  echo "$found"
  echo "check_function_size: library functions over 80 lines (split them, or write why beside a NOLINTNEXTLINE)" >&2
  exit 1
fi
echo "check_function_size: no library function over 80 lines without a written reason"
