// The lanes and warp decoders in plain C++ (any CPU): the fallback where no
// SIMD instruction set is available, and the same algorithms as the SIMD
// builds, lane by lane.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "core/block_geometry.hpp"
#include "decode/decode_kernels.hpp"

namespace fiblet::detail::portable {

#include "decode/simd_portable.inl"
//
#include "decode/decode_lanes.inl"
#include "decode/decode_warp.inl"

const KernelSet kKernels{decode_lanes, decode_warp, decode_lanes16};

}  // namespace fiblet::detail::portable
