// The lanes and warp decoders built for AVX2 + FMA (8 float lanes). Every
// header is included before the target pragma, so only the functions defined
// here use AVX2: the dispatcher calls them only on CPUs that have it.
#include "decode/decode_kernels.hpp"

#ifdef FIBLET_HAVE_X86_KERNELS
#include <immintrin.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "core/block_geometry.hpp"

#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2,fma,bmi,bmi2,popcnt"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2,fma,bmi,bmi2,popcnt")
#endif

namespace fiblet::detail::avx2 {

#include "decode/simd_avx2.inl"
//
#include "decode/decode_lanes.inl"
#include "decode/decode_warp.inl"

const KernelSet kKernels{decode_lanes, decode_warp, decode_lanes16};

}  // namespace fiblet::detail::avx2

#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

#endif  // FIBLET_HAVE_X86_KERNELS
