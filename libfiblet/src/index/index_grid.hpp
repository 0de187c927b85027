// Internal: the grid of the block index (formats/fft-index.md) and a
// block's box on it, as the per-block streams of BIDX versions 3 and 4 code it.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fiblet/fft_format.hpp"
#include "fiblet/view.hpp"

namespace fiblet::detail {

// A box on the index grid: per axis, the cells lo .. lo + extent.
struct GridBox {
    std::array<std::uint16_t, 3> lo{};  // < kMaxGridLevels
    std::array<std::uint8_t, 3> extent{};
    bool operator==(const GridBox&) const = default;
};

inline constexpr std::uint32_t kMaxBoxExtent = 15;  // extents 0..15 cells
// lo < levels <= 1024: a cell stays above 1/1024 of the range, so that the
// 0.001-cell slack of quantized boxes exceeds the float rounding of
// coordinates (2^-24 of their magnitude).
inline constexpr std::uint32_t kMaxGridLevels = 1u << 10;
// Bits of a lo coded whole on a grid of `levels` positions (at least 1).
inline unsigned level_bits(std::uint32_t levels) { return unsigned(std::bit_width(levels > 1 ? levels - 1 : 1u)); }

// Every finite point: a block may lie anywhere in the float range.
inline Aabb unbounded_box() {
    const float m = std::numeric_limits<float>::max();
    return {{-m, -m, -m}, {m, m, m}};
}

// A grid box in 64 bits, as an index keeps one per block in memory: per
// axis a, lo in the low `lo_bits` of bits a * axis_bits() on and the extent
// above it, in cells of 1 / `subdivision` of the grid's; all ones:
// unbounded.
struct CellLayout {
    unsigned lo_bits, extent_bits, subdivision;
    constexpr unsigned axis_bits() const { return lo_bits + extent_bits; }
};
// A block's box (GridBox: lo < 1024, extent <= 15 cells), and a box within
// one in quarter cells (sides up to 4 * (1023 + 15), extents up to 60).
inline constexpr CellLayout kGridCells{10, 4, 1}, kQuarterCells{13, 6, 4};
inline constexpr std::uint64_t kUnboundedCells = ~std::uint64_t{0};

template <CellLayout L = kGridCells>
std::uint64_t pack_cells(const std::uint32_t lo[3], const std::uint32_t hi[3]) {
    std::uint64_t v = 0;
    for (int a = 0; a < 3; ++a) v |= std::uint64_t(lo[a] | (hi[a] - lo[a]) << L.lo_bits) << (L.axis_bits() * a);
    return v;
}
inline std::uint64_t pack_cells(const GridBox& b) {
    std::uint32_t lo[3], hi[3];
    for (int a = 0; a < 3; ++a) lo[a] = b.lo[a], hi[a] = lo[a] + b.extent[a];
    return pack_cells(lo, hi);
}
template <CellLayout L = kGridCells>
std::uint32_t cells_lo(std::uint64_t v, int axis) {
    return std::uint32_t(v >> (L.axis_bits() * axis)) & ((1u << L.lo_bits) - 1);
}
template <CellLayout L = kGridCells>
std::uint32_t cells_hi(std::uint64_t v, int axis) {
    return cells_lo<L>(v, axis) + (std::uint32_t(v >> (L.axis_bits() * axis + L.lo_bits)) & ((1u << L.extent_bits) - 1));
}
// The box in mm of cells lo .. hi of size `cell`: sides at origin +
// float(i) * cell, as IndexBoxDecoder computes version-2 boxes.
inline Aabb cells_bounds(const std::uint32_t lo[3], const std::uint32_t hi[3], Vec3f origin, float cell) {
    auto side = [&](float o, std::uint32_t i) { return o + float(i) * cell; };
    return {{side(origin.x, lo[0]), side(origin.y, lo[1]), side(origin.z, lo[2])},
            {side(origin.x, hi[0]), side(origin.y, hi[1]), side(origin.z, hi[2])}};
}
// A packed box in mm on a grid of cells `cell` (quarter cells: sides at
// float(4 i) * cell / 4, those of the grid's cells exactly).
template <CellLayout L = kGridCells>
Aabb cells_bounds(std::uint64_t packed, Vec3f origin, float cell) {
    if (packed == kUnboundedCells) return unbounded_box();
    const std::uint32_t lo[3] = {cells_lo<L>(packed, 0), cells_lo<L>(packed, 1), cells_lo<L>(packed, 2)},
                        hi[3] = {cells_hi<L>(packed, 0), cells_hi<L>(packed, 1), cells_hi<L>(packed, 2)};
    return cells_bounds(lo, hi, origin, cell / float(L.subdivision));
}

// Boxes are stored on a cubic grid: on each axis a box is [origin + i*cell,
// origin + (i+e)*cell] with i < min_levels and e < extent_levels. Versions
// 1 and 2 store a box as one code: the three axis codes i*extent_levels + e
// in mixed radix (x fastest), the all-ones code of `bits` bits meaning
// "unbounded" (a group that does not fit the grid). Versions 3 and 4 code i
// and e themselves (GridBox).
struct IndexGrid {
    Vec3f origin{};
    float cell = 1;
    std::uint32_t min_levels = 1, extent_levels = 1;
    unsigned bits = 28;  // versions 1 and 2

    std::uint32_t axis_levels() const { return min_levels * extent_levels; }
    std::uint32_t unbounded_code() const { return bits >= 32 ? 0xffffffffu : (1u << bits) - 1; }

    // The grid of versions 3 and 4 of a file: covers the normalized cube (with a
    // margin) in cells of half a block's path.
    static IndexGrid for_blocks(const FftHeader& h);
    // The version-2 grid of a file: covers the normalized cube (with a
    // margin) and makes the cells as small as `bits` allow for groups of
    // `group_blocks` blocks, up to group_blocks * points_per_block steps across.
    static IndexGrid for_groups(const FftHeader& h, unsigned bits, std::uint32_t group_blocks);
    // Conservative grid box of a box (its bounds contain it, with a small
    // slack for float rounding), or nullopt when it does not fit the grid.
    std::optional<GridBox> quantize(const Aabb& box) const;
    Aabb bounds(std::uint64_t packed_cells) const { return cells_bounds(packed_cells, origin, cell); }
    std::optional<std::pair<std::uint32_t, std::uint32_t>> axis_cells(float o, float lo, float hi) const;
    // Version 2: the conservative code of a box (the decoded box contains
    // it, with the same slack), or unbounded_code().
    std::uint32_t encode(const Aabb& box) const;
};

// A box at least this large is unbounded (is_unbounded()).
inline constexpr float kUnboundedExtentMm = 1e30f;

// What a stream decodes to: a box per block (pack_cells, or
// kUnboundedCells), or an error message for a malformed stream (its users
// report an fft_format error).
struct DecodedBoxes {
    std::vector<std::uint64_t> boxes;
    std::string error;  // empty when well-formed
};

}  // namespace fiblet::detail
