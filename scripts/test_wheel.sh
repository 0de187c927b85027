#!/usr/bin/env bash
# Builds the fiblet wheel (pip, from Debian's packages: --no-build-isolation)
# reusing the configured build tree BUILD_DIR, installs it into a fresh
# virtual environment (--system-site-packages: numpy, nibabel and DIPY from
# Debian) and runs python/tests against the installed package, from outside
# the source tree so that nothing else can be imported.
#   scripts/test_wheel.sh BUILD_DIR
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$(cd "${1:?usage: test_wheel.sh BUILD_DIR}" && pwd)"
python="${PYTHON:-/usr/bin/python3}"
work="$build/wheel-test"
rm -rf "$work"
mkdir -p "$work/dist" "$work/run"
(cd "$root" && FIBLET_CMAKE_BUILD_DIR="$build" "$python" -m pip wheel -q --no-build-isolation --no-deps \
  -w "$work/dist" .)
"$python" -m venv --system-site-packages "$work/venv"
"$work/venv/bin/python" -m pip install -q --no-index --no-deps "$work/dist"/fiblet-*.whl
cd "$work/run"
unset PYTHONPATH
"$work/venv/bin/python" -c "import fiblet, sys; assert fiblet.__file__.startswith('$work/venv'), fiblet.__file__; print('installed', fiblet.__version__, 'at', fiblet.__file__)"
exec "$work/venv/bin/python" -m pytest -q -rs -p no:cacheprovider "$root/python/tests"
