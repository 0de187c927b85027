# Sourced by the benchmark scripts: the source root, the build and output
# folders, and the medium tractogram (46 M points, iFOD1 0.1 mm; made once
# by shared/data/make-tractograms.sh, about 80 s on a quiet machine).
# Environment: FIBLET_BUILD_DIR (default build/), OUT (default bench/),
# FIBLET_BENCH_DATA (default build/bench-data).
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${FIBLET_BUILD_DIR:-$root/build}"
out="${OUT:-$root/bench}"
data="${FIBLET_BENCH_DATA:-$build/bench-data}"

# Prints the medium tractogram's path, making it first if missing.
medium_tractogram() {
  local tck="$data/medium-ifod1.tck"
  if [ ! -f "$tck" ]; then
    mkdir -p "$data"
    "$root/../shared/data/make-tractograms.sh" -o "$data" medium >&2
  fi
  echo "$tck"
}
