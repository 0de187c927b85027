// The lanes and warp decoders built for AVX-512 F, BW, DQ and VL (16 float lanes). Every
// header is included before the target pragma, so only the functions defined
// here use AVX-512: the dispatcher calls them only on CPUs that have it.
#include "decode/decode_kernels.hpp"

#ifdef FIBLET_HAVE_X86_KERNELS
// GCC 12 warns about the deliberately undefined source of its own
// AVX-512 intrinsics (_mm512_undefined_*) in every inlined use.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#include <immintrin.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "core/block_geometry.hpp"

#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx512f,avx512bw,avx512dq,avx512vl,avx2,fma,bmi,bmi2,popcnt"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx512f,avx512bw,avx512dq,avx512vl,avx2,fma,bmi,bmi2,popcnt")
#endif

namespace fiblet::detail::avx512 {

#include "decode/simd_avx512.inl"
//
#include "decode/decode_lanes.inl"
#include "decode/decode_warp.inl"

const KernelSet kKernels{decode_lanes, decode_warp, decode_lanes16};

}  // namespace fiblet::detail::avx512

#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

#endif  // FIBLET_HAVE_X86_KERNELS
