// Internal: the SIMD decoders, one set per instruction set. Each kernel
// decodes `count` blocks whose point counts were validated, into `xyz`, and
// returns the number of points written (as decode_blocks_scalar does).
//
// The kernels are written once (decode_lanes.inl, decode_warp.inl) against a
// small vector type `V` and compiled three times: plain C++ (portable), AVX2
// and AVX-512, each in its own file under `#pragma GCC target`, so one binary
// runs on any x86-64 and picks at run time (decode_dispatch.cpp).
//
// Why intrinsics rather than Highway (libhwy-dev), by measurement
// (bench/highway_lanes_bench.cpp, the same lanes decoder in Highway 1.0.3,
// bit-identical output; Zen 4, CPU time, points/s): Highway's GatherIndex
// version 245 M (AVX-512) / 156 M (AVX2); with the table rows transposed by
// ConcatOdd/ConcatEven 387 M / 118 M; these intrinsics 696 M / 507 M. The
// decoder lives on transposes, and x86's in-lane unpacks and 128-bit-lane
// shuffles do them in half the instructions of a portable unzip; the
// dispatch Highway would bring is 30 lines here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "fiblet/decode.hpp"

namespace fiblet::detail {

using BlockKernel = std::size_t (*)(const DecodeContext&, const std::uint8_t* blocks, std::size_t count, float* xyz);

struct KernelSet {
    BlockKernel lanes;
    BlockKernel warp;
    BlockKernel lanes16;  // the lanes decoder for 16-bit blocks (formats/fft16.md)
};

// How V::lookup reads a block's direction code: a byte (version 2) or a
// little-endian u16 (16-bit blocks, in memory as BlockView16 reads them).
struct Code8 {
    static unsigned at(const std::uint8_t* p) { return *p; }
};
struct Code16 {
    static unsigned at(const std::uint8_t* p) { return unsigned(p[0]) | unsigned(p[1]) << 8; }
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

// Component 3 col + row of `f` at row[3 col + row] (DecodeContext::frame_rows).
void put_frame_row(const Frame& f, float* row);
// A 16-bit header's rows, shared by every context of the same table (null for version 2).
std::shared_ptr<const DecodeContext::FrameRows16> frame_rows16_of(const FftHeader& header);

// Decodes validated blocks on the calling thread with a decoder already
// resolved by resolve_decoder().
std::size_t decode_resolved(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count, float* xyz,
                            Decoder resolved);

}  // namespace fiblet::detail
