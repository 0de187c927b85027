// Internal: bitmaps of blocks (bit b of word b / 64 for block b), as the
// block index hands them out.
#pragma once

#include <cstdint>
#include <vector>

namespace fiblet::detail {

using BlockBits = std::vector<std::uint64_t>;

inline bool has_bit(const BlockBits& bits, std::uint64_t i) { return (bits[i >> 6] >> (i & 63)) & 1; }

// Whether any of bits [first, end) is set, a word at a time.
inline bool any_bit(const BlockBits& bits, std::uint64_t first, std::uint64_t end) {
    if (first >= end) return false;
    const std::uint64_t w0 = first >> 6, w1 = (end - 1) >> 6;
    const std::uint64_t from_first = ~std::uint64_t{0} << (first & 63),
                        to_last = ~std::uint64_t{0} >> (63 - ((end - 1) & 63));
    if (w0 == w1) return bits[w0] & from_first & to_last;
    if (bits[w0] & from_first) return true;
    for (std::uint64_t w = w0 + 1; w < w1; ++w)
        if (bits[w]) return true;
    return bits[w1] & to_last;
}

}  // namespace fiblet::detail
