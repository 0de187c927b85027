// Internal: the box stream of a BIDX version-4 chunk (formats/fft-index.md
// §2): a box per block coded against the previous block's box of its fiber,
// one static order-1 model per axis, with three interleaved rANS states
// (one an axis), so that decoding is three independent chains of table
// lookups instead of version 3's single serial chain of binary decisions.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "index/index_grid.hpp"

namespace fiblet::detail {

// The stream of `boxes` (pack_cells, or kUnboundedCells), first_of_fiber[b]
// telling where fibers start: its frequency tables, then its 32-bit words.
std::vector<std::uint8_t> encode_box_rans(const std::vector<std::uint64_t>& boxes,
                                          const std::vector<bool>& first_of_fiber, std::uint32_t levels);

// Decodes a box per block; a malformed stream (bad tables, a box off the
// grid, a stream shorter or longer than its boxes, states that do not end
// where the encoder started them) gives an error message.
DecodedBoxes decode_box_rans(const std::uint8_t* data, std::size_t size, const std::vector<bool>& first_of_fiber,
                             std::uint32_t levels);

}  // namespace fiblet::detail
