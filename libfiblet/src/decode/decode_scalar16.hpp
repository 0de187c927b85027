// Internal: decoding whole fibers of a 16-bit file (the hook that
// decode_fibers.cpp dispatches 16-bit files to).
#pragma once

#include <cstdint>
#include <vector>

#include "fiblet/decode.hpp"

namespace fiblet::detail {

// Decodes fibers [begin, end) whose blocks are in `blocks`.
void decode_fiber_range16(const FftFile& file, const DecodeContext& ctx, std::uint64_t begin, std::uint64_t end,
                          const std::vector<std::uint8_t>& blocks, Streamlines& out);

}  // namespace fiblet::detail
