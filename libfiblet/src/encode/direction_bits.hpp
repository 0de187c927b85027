// Internal: whether a file's fibers keep their lengths at 8 bits a direction.
// The 8-bit code grid has no code exactly straight ahead (formats/fft.md §4),
// so a smooth fiber zig-zags by at least the grid's smallest turn and each
// decoded step is longer than its chord: a long smooth fiber grows by
// L (1 - cos theta_min), far beyond its point error (docs/encode.md, "Why
// smooth fibers need 16 bits"). 16-bit codes are 16 times finer and keep
// such lengths; jittery tractography (iFOD1/iFOD2) turns more than the grid
// anyway and keeps them at 8 bits.
#pragma once

#include <span>
#include <vector>

#include "fiblet/compress.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/geometry.hpp"

namespace fiblet::detail {

// How the file's fibers are resampled before they are encoded (pass 1b):
// step_mm = 0 when they are encoded as they are.
struct SampleResampling {
    double step_mm = 0, stretch = 1;
};

// Points in the sample the bits are chosen on (FiberSample: every k-th
// fiber of two points or more). Larger than the tuning
// sample (16 k points): the length change that decides is a max over
// fibers, and 16 k points are 7 of CST_R-step0.1's 50 fibers and 15 of
// cingulum-2-step0.1's 113, which miss the few whose lengths 8-bit codes
// change beyond the point error; 64 k points catch them, 128 k hold every
// shared 0.1 mm bundle whole (docs/encode.md, "Why smooth fibers need 16
// bits"). Encoding them costs ~7 % of compressing a 2 M-point file
// (0.05 s of CPU on small-ifod1), 0.3 % of a 46 M-point one.
inline constexpr std::size_t kBitsSamplePoints = std::size_t{1} << 17;

// Encodes each of `fibers` as pass 2 would with `encoder` (resampled first
// as `resampling` says, its end kept) and measures, over float32 and exact
// decodes alike, each fiber's length change against its input polyline and
// the point error (the header's measure). Fills every field of the result
// but `automatic` and `reason`. On `threads` threads, the same result for any.
DirectionBitsChoice measure_sample_lengths(std::span<const std::vector<Vec3f>> fibers, const FiberEncoder& encoder,
                                           SampleResampling resampling, unsigned threads);

// 16 bits when the 8-bit codes' largest length change on the sample exceeds
// kLengthOverPointError times the sample's max point error. The sample's
// max point error is below the file's, and its largest length change below
// the file's largest by about as much (fewer fibers): their ratio is what
// the file sees (measured on the shared files: docs/encode.md).
inline constexpr double kLengthOverPointError = 1.0;
bool eight_bits_keep_lengths(const DirectionBitsChoice& measured);

}  // namespace fiblet::detail
