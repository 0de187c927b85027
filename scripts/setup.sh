#!/usr/bin/env bash
# Installs fiblet's dependencies from Debian's packages. Idempotent: quick
# when everything is already installed.
#   scripts/setup.sh            everything the whole test suite needs
#   scripts/setup.sh --minimal  the library, the CLI and the Python module
#                               (pip install --no-build-isolation .) only
set -euo pipefail

MINIMAL=(
  build-essential cmake ninja-build pkg-config
  libcli11-dev libeigen3-dev libfmt-dev libzstd-dev libxxhash-dev
  libzip-dev nlohmann-json3-dev libhwy-dev
  libnifti2-dev  # NIfTI images (masks)
  python3 python3-dev python3-numpy python3-pybind11 pybind11-dev
  python3-pip python3-venv python3-setuptools python3-wheel  # pip install . / the wheel test
)
PACKAGES=(
  "${MINIMAL[@]}"
  libgtest-dev libgmock-dev libbenchmark-dev
  python3-nibabel python3-matplotlib python3-pytest snakemake
  python3-dipy  # fiblet.load_sft() and its test
  mrtrix3 zstd time
  valgrind  # callgrind: the compress instruction budget (bench/instruction_budget.py)
  slurm-wlm munge  # the cohort workflow on a single-node SLURM (ecosystem.cohort_workflow_slurm)
  clang-14 libclang-rt-14-dev  # libFuzzer harnesses (scripts/fuzz.sh)
  clang-tidy-14  # library functions over 80 lines only with a reason (scripts/check_function_size.sh)
  libglfw3-dev libepoxy-dev libegl-dev libegl-mesa0 libgl1-mesa-dri libspng-dev
  libimgui-dev  # the viewer's control panel
  xvfb xdotool  # the window test (scripts/view_window_test.sh): a virtual display, keys and clicks
  libembree-dev  # test-only: the independent ray tracer the viewer's capsules are checked against
)

case "${1:-}" in
  --minimal) PACKAGES=("${MINIMAL[@]}") ;;
  "") ;;
  *) echo "setup.sh: unknown argument $1 (--minimal or nothing)" >&2; exit 2 ;;
esac

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get -o DPkg::Lock::Timeout=600 update -qq
  $SUDO apt-get -o DPkg::Lock::Timeout=600 install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
