// Internal: the SIMD decoders, one set per instruction set. Each kernel
// decodes `count` blocks whose point counts were validated, into `xyz`, and
// returns the number of points written (as decode_blocks_scalar does).
//
// The kernels are written once (decode_lanes.inl, decode_warp.inl) against a
// small vector type `V` and compiled three times: plain C++ (portable), AVX2
// and AVX-512, each in its own file under `#pragma GCC target`, so one binary
// runs on any x86-64 and picks at run time (decode_dispatch.cpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include "fiblet/decode.hpp"

namespace fiblet::detail {

using BlockKernel = std::size_t (*)(const DecodeContext&, const std::uint8_t* blocks, std::size_t count, float* xyz);

struct KernelSet {
    BlockKernel lanes;
    BlockKernel warp;
};

namespace portable {
extern const KernelSet kKernels;
}
#if defined(__x86_64__) || defined(__i386__)
#define FIBLET_HAVE_X86_KERNELS 1
namespace avx2 {
extern const KernelSet kKernels;
}
namespace avx512 {
extern const KernelSet kKernels;
}
#endif

// Decodes validated blocks on the calling thread with a decoder already
// resolved by resolve_decoder().
std::size_t decode_resolved(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count, float* xyz,
                            Decoder resolved);

}  // namespace fiblet::detail
