// Internal: the range-coded stream of per-block grid boxes of a BIDX
// version-3 chunk (formats/fft-index.md §7): each block's box is coded
// against the previous block's, with adaptive binary models. Read, no
// longer written: its single serial chain of binary decisions made the
// index slow to load (version 4, box_rans.hpp, replaced it).
#pragma once

#include <array>
#include <cstdint>

#include "index/index_grid.hpp"

namespace fiblet::detail {

// The adaptive models and the previous box, updated block after block as
// the encoder did.
class BoxModel {
public:
    explicit BoxModel(std::uint32_t levels);
    std::uint32_t levels() const { return levels_; }
    unsigned level_bits() const { return level_bits_; }

protected:
    // Values are coded in unary (a bit "more" per step, with its own
    // probability): the common small values take few of the coder's serial
    // steps, which bound the load time.
    static constexpr std::uint32_t kEscape = 31;  // zigzag deltas 0..30; 31: lo follows in level_bits bits
    static constexpr std::uint32_t kContextExtents = 8;  // extents above 7 share a context
    struct Axis {
        std::uint32_t lo = 0, extent = 0;
        std::uint32_t sign = 3;  // of the last delta: 0 negative, 1 zero, 2 positive, 3 coded whole
        // Contexts: the last delta's sign and extent (and, for deltas, the box's extent).
        std::array<std::array<std::uint16_t, kMaxBoxExtent>, 4 * kContextExtents> extent_steps;
        std::array<std::array<std::uint16_t, kEscape>, 4 * kContextExtents * kContextExtents> delta_steps;
        std::uint16_t* extent_context() { return extent_steps[sign * kContextExtents + capped(extent)].data(); }
        std::uint16_t* delta_context(std::uint32_t e) {
            return delta_steps[(sign * kContextExtents + capped(extent)) * kContextExtents + capped(e)].data();
        }
        static std::uint32_t capped(std::uint32_t e) { return e < kContextExtents ? e : kContextExtents - 1; }
    };
    std::uint16_t bounded_;  // probability that a block has a box
    std::array<Axis, 3> axes_;
    std::uint32_t levels_;
    unsigned level_bits_;
};

// Decodes a box per block (pack_cells, or kUnboundedCells), first_of_fiber[b]
// telling where fibers start. A malformed stream (a box off the grid, a
// stream shorter or longer than its boxes) gives an error message, which
// the chunk's users report as an fft_format error.
DecodedBoxes decode_box_stream(const std::uint8_t* data, std::size_t size,
                               const std::vector<bool>& first_of_fiber, std::uint32_t levels);

}  // namespace fiblet::detail
