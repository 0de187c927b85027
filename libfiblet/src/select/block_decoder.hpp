// Internal: the one place where the selection code decodes blocks, so that
// switching it to the fastest decoder is a one-line change.
#pragma once

#include <cstddef>
#include <cstdint>

#include "fiblet/decode.hpp"

namespace fiblet::detail {

// Decodes `count` blocks (already validated by count_block_points) into
// xyz, with the fastest decoder this CPU runs, on the calling thread.
inline std::size_t decode_selected_blocks(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count,
                                          float* xyz) {
    return decode_blocks(ctx, blocks, count, xyz);
}

}  // namespace fiblet::detail
