// fiblet — keeping each fiber's true end point (the ENDS trailer chunk).
//
// The codec walks a fixed step, so a streamline whose length is not a whole
// number of steps cannot end where its input does. The encoder appends one
// more full step aimed at the true end point, and stores per fiber the
// fraction f of that last step to keep; every fiblet decoder then places the
// fiber's last point at  p_prev + f * (p_last - p_prev)  (formats/fft-ends.md).
// f <= 1, so the kept point lies on the decoded last segment: bounding boxes,
// culling and the block index of the unshortened points stay conservative,
// and a reader that ignores the chunk sees at most one step more.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "fiblet/fft_format.hpp"
#include "fiblet/geometry.hpp"

namespace fiblet {

// "ENDS" chunk: one u16 per fiber (in fiber order), f = value / 65535.
inline constexpr std::array<char, 4> kFiberEndsTag = {'E', 'N', 'D', 'S'};
// The value that leaves a fiber as the blocks decode it.
inline constexpr std::uint16_t kWholeLastStep = 65535;

// Per-fiber fractions as a decoder uses them.
using FiberEndFractions = std::vector<std::uint16_t>;

inline std::uint16_t quantize_end_fraction(double f) {
    const double c = f < 0 ? 0.0 : (f > 1 ? 1.0 : f);
    return std::uint16_t(c * 65535.0 + 0.5);
}
inline float end_fraction(std::uint16_t q) { return float(q) / 65535.0f; }

// The last point as every decoder computes it (float32, component by
// component, so the encoder's measurement and the decoders agree bit for bit).
inline Vec3f place_end_point(Vec3f prev, Vec3f last, std::uint16_t q) {
    const float f = end_fraction(q);
    return {prev.x + f * (last.x - prev.x), prev.y + f * (last.y - prev.y), prev.z + f * (last.z - prev.z)};
}

// Only a last block with three points or more has a direction-coded last
// point; in shorter ones the last point is an anchor, which the encoder sets
// to the true end point (rounded to keep the fiber's length, within its point
// error; formats/fft-ends.md) — the fraction is then ignored.
inline bool end_fraction_applies(std::uint32_t block_points) { return block_points >= 3; }

TrailerChunk make_fiber_ends_chunk(std::span<const std::uint16_t> fractions);
// Validates the payload size against the fiber count (Error{fft_format}, naming `path`).
FiberEndFractions parse_fiber_ends_chunk(const TrailerChunk& chunk, std::uint64_t fibers, const std::string& path);

// Applies the fractions to decoded blocks: `xyz` holds the points of
// `count` consecutive blocks (world mm, as the decoders write them). For
// each block that is its fiber's last with three points or more, the last
// point moves to place_end_point(). Fiber IDs outside the table are left alone
// (the block structure was validated against the LUT before decoding).
void apply_fiber_ends(const FftHeader& header, const FiberEndFractions& fractions, const std::uint8_t* blocks,
                      std::size_t count, float* xyz);

}  // namespace fiblet
