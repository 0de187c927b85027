// Internal: runs of whole fibers sized in blocks, for the readers that
// split a file into parts (decode_fibers, kept_fibers).
#pragma once

#include <cstdint>

#include "fiblet/fft_file.hpp"

namespace fiblet::detail {

// The end of the whole fibers from `f` (up to `end`) within `max_blocks`
// blocks, at least one fiber. Fibers' first blocks increase: a binary search.
inline std::uint64_t fibers_end(const FftFile& file, std::uint64_t f, std::uint64_t end, std::uint64_t max_blocks) {
    const std::uint64_t b0 = file.block_end(f);
    std::uint64_t lo = f + 1, hi = end;
    while (lo < hi) {
        const std::uint64_t mid = lo + (hi - lo + 1) / 2;
        if (file.block_end(mid) - b0 <= max_blocks) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

}  // namespace fiblet::detail
