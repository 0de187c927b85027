#!/usr/bin/env bash
# Installs the build tree into a temporary prefix, then builds and runs a
# downstream program against that install twice: through CMake's
# find_package(fiblet) and through pkg-config. Also runs the installed CLI
# and, given PYTHON, imports the installed Python package.
#   run_downstream_test.sh BUILD_DIR INPUT.tck EXPECTED_VERSION [PYTHON]
set -euo pipefail
build="$1" input="$2" version="$3"
here="$(cd "$(dirname "$0")" && pwd)"
tmp="$(mktemp -d "${TMPDIR:-/tmp}/fiblet-downstream.XXXXXX")"
trap 'rm -rf "$tmp"' EXIT
prefix="$tmp/prefix"

cmake --install "$build" --prefix "$prefix" >/dev/null
for f in bin/fiblet include/fiblet/fiblet.hpp; do
  [ -e "$prefix/$f" ] || { echo "missing after install: $f" >&2; exit 1; }
done
config="$(find "$prefix" -name fibletConfig.cmake)"
pc="$(find "$prefix" -name fiblet.pc)"
[ -n "$config" ] && [ -n "$pc" ] || { echo "no fibletConfig.cmake or fiblet.pc installed" >&2; exit 1; }
echo "installed: ${config#$prefix/}, ${pc#$prefix/}"

got="$("$prefix/bin/fiblet" --version)"
[ "$got" = "fiblet $version" ] || { echo "installed fiblet --version: '$got', expected 'fiblet $version'" >&2; exit 1; }

echo "== find_package(fiblet)"
# (CXXFLAGS/LDFLAGS from the environment: CMake reads them on first configure.)
cmake -S "$here" -B "$tmp/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$tmp/build" >/dev/null
"$tmp/build/downstream" "$input" "$tmp/cmake.fft"

echo "== pkg-config fiblet"
export PKG_CONFIG_PATH="$(dirname "$pc")"
[ "$(pkg-config --modversion fiblet)" = "$version" ] || { echo "pkg-config version mismatch" >&2; exit 1; }
# The rpath matters for a shared libfiblet in this non-system prefix only.
# shellcheck disable=SC2046
${CXX:-c++} ${CXXFLAGS:-} -O1 "$here/main.cpp" -o "$tmp/pc-downstream" $(pkg-config --cflags --libs fiblet) ${LDFLAGS:-} \
  -Wl,-rpath,"$(pkg-config --variable=libdir fiblet)"
"$tmp/pc-downstream" "$input" "$tmp/pc.fft"

# The Python package, when it was built: importable from the prefix alone.
module="$(find "$prefix" -name '_fiblet*.so' | head -1)"
if [ -n "$module" ] && [ -n "${4:-}" ]; then
  echo "== python: import fiblet from ${module#$prefix/}"
  PYTHONPATH="$(dirname "$(dirname "$module")")" "$4" -c '
import sys, fiblet
assert fiblet.__file__.startswith(sys.argv[1]), fiblet.__file__
s = fiblet.load(sys.argv[2])
assert len(s) == fiblet.info(sys.argv[2])["fibers"] > 0
print(f"python: {s!r}")' "$prefix" "$tmp/cmake.fft"
fi
