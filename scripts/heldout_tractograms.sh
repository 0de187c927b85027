#!/usr/bin/env bash
# Held-out tractograms for accuracy checks (docs/encode.md): the shared data's
# phantom (make_phantom_fod.py) tracked with seeds the shared files do not use,
# so that settings tuned on ../shared/data can be checked on data they never saw.
# Usage: scripts/heldout_tractograms.sh OUTDIR   (needs mrtrix3, python3-numpy/scipy/nibabel)
set -euo pipefail
out=${1:?usage: $0 OUTDIR}
shared="$(cd "$(dirname "$0")/../../shared/data" && pwd)"
mkdir -p "$out"
cd "$out"
[ -f phantom-fod.nii ] || /usr/bin/python3 "$shared/make_phantom_fod.py" . >/dev/null
export MRTRIX_QUIET=1
track() {  # NAME SEED ARGS...
  local name=$1 seed=$2; shift 2
  [ -f "$name.tck" ] || MRTRIX_RNG_SEED=$seed tckgen -force -nthreads 0 -seed_image phantom-mask.nii \
    -minlength 20 -maxlength 250 "$@" phantom-fod.nii "$name.tck"
}
track heldout-ifod1-s7001 7001 -algorithm iFOD1 -step 0.1 -select 1000
track heldout-ifod1-s7002 7002 -algorithm iFOD1 -step 0.1 -select 1000
track heldout-ifod1-step0.05-s7003 7003 -algorithm iFOD1 -step 0.05 -select 500
track heldout-sdstream-s7004 7004 -algorithm SD_STREAM -step 0.1 -select 1000
track heldout-ifod1-step0.2-s7005 7005 -algorithm iFOD1 -step 0.2 -select 1000
ls -l "$out"/*.tck
