// Internal: the packed blocks of version 17 (formats/fft16.md) and the
// in-memory 16-bit block layout (BlockView16) they expand to. The encoder
// writes in-memory blocks and packs them; FftFile reads packed blocks and
// expands them, so decoders, selection and checksums see one layout.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "fiblet/fft_format.hpp"

namespace fiblet::detail {

// Appends the packed form of in-memory blocks (h.block_bytes() each) to `out`.
void pack_blocks16(const FftHeader& h, std::span<const std::uint8_t> blocks, std::vector<std::uint8_t>& out);

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
