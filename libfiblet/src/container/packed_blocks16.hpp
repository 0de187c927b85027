// Internal: the packed blocks of version 17 (formats/fft16.md) and the
// in-memory 16-bit block layout (BlockView16) they expand to. The encoder
// writes in-memory blocks and packs them; FftFile reads packed blocks and
// expands them, so decoders, selection and checksums see one layout.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/vec_math.hpp"
#include "fiblet/fft_format.hpp"

namespace fiblet::detail {

// Version 17's first-frame axis: the difference of the anchors' unorm24
// integers, normalized. The integers are exact in a float, so a float
// decoder and an exact one agree up to the rounding of the normalization
// (version 16 normalizes the difference of the float anchors, whose rounding
// can turn the axis by about 3e-5 rad at a 0.1 mm step: about 0.8 um at
// the end of a 254-point block).
inline Vec3f packed16_anchor_axis(const BlockView16& b) {
    auto diff = [&](int i) { return float(std::int32_t(b.anchor_word(3 + i)) - std::int32_t(b.anchor_word(i))); };
    const Vec3f d{diff(0), diff(1), diff(2)};
    const float n2 = dot(d, d);
    return n2 > 0.0f ? (1.0f / std::sqrt(n2)) * d : Vec3f{1.0f, 0.0f, 0.0f};
}

// Appends the packed form of in-memory blocks (h.block_bytes() each) to `out`,
// and each packed block's size to `sizes` when given (the checksum groups
// count blocks: fft-checksum.md).
void pack_blocks16(const FftHeader& h, std::span<const std::uint8_t> blocks, std::vector<std::uint8_t>& out,
                   std::vector<std::uint32_t>* sizes = nullptr);

// Where a packed block sits in its fiber: the fields the packed layout
// leaves out (they follow from the fiber LUT).
struct PackedBlockPlace {
    std::uint32_t points;  // in this block: pointsPerBlock but in a fiber's last block
    std::uint32_t fiber_id;
    bool first, last;
};

// Expands the packed block at `packed` (packed16_block_bytes(place.points)
// bytes) into the in-memory block `out` (h.block_bytes() bytes). Returns an
// empty string, or what is malformed (a code past the 181 x 181 levels,
// non-zero bits after the last code).
std::string expand_block16(const FftHeader& h, const std::uint8_t* packed, const PackedBlockPlace& place,
                           std::uint8_t* out);

}  // namespace fiblet::detail
