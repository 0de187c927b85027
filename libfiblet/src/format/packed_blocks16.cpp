#include "format/packed_blocks16.hpp"

#include <cstring>

namespace fiblet::detail {

namespace {

constexpr std::uint32_t kCodeMask = (1u << kPacked16CodeBits) - 1;

std::uint16_t get_u16(const std::uint8_t* p) { return std::uint16_t(p[0] | p[1] << 8); }

}  // namespace

void pack_blocks16(const FftHeader& h, std::span<const std::uint8_t> blocks, std::vector<std::uint8_t>& out) {
    const std::size_t bb = h.block_bytes();
    for (std::size_t at = 0; at + bb <= blocks.size(); at += bb) {
        const std::uint8_t* b = blocks.data() + at;
        const std::uint32_t n = get_u16(b + kBlock16FlagsOffset) & kFlag16CountMask;
        const std::size_t start = out.size();
        out.resize(start + packed16_block_bytes(n));
        std::uint8_t* p = out.data() + start;
        std::memcpy(p, b, kPacked16AnchorBytes);
        p += kPacked16AnchorBytes;
        // The codes as one bit stream, least significant bit first.
        std::uint64_t acc = 0;
        unsigned bits = 0;
        for (std::uint32_t k = 0; k + 2 < n; ++k) {
            acc |= std::uint64_t(get_u16(b + kBlock16DirectionsOffset + 2 * k) & kCodeMask) << bits;
            for (bits += kPacked16CodeBits; bits >= 8; bits -= 8, acc >>= 8) *p++ = std::uint8_t(acc);
        }
        if (bits > 0) *p++ = std::uint8_t(acc);
    }
}

std::string expand_block16(const FftHeader& h, const std::uint8_t* packed, const PackedBlockPlace& place,
                           std::uint8_t* out) {
    std::memset(out, 0, h.block_bytes());
    std::memcpy(out, packed, kPacked16AnchorBytes);
    const std::uint32_t id = place.fiber_id;
    std::memcpy(out + kBlock16FiberIdOffset, &id, 4);  // hosts are little-endian (checked in CMake)
    const std::uint16_t flags = std::uint16_t((place.first ? 0u : kFlag16NotFirst) | (place.last ? 0u : kFlag16NotLast) |
                                              place.points);
    out[kBlock16FlagsOffset] = std::uint8_t(flags), out[kBlock16FlagsOffset + 1] = std::uint8_t(flags >> 8);
    const std::uint8_t* p = packed + kPacked16AnchorBytes;
    std::uint8_t* codes = out + kBlock16DirectionsOffset;
    const std::uint32_t levels = h.code_levels(), code_count = levels * levels;
    std::uint64_t acc = 0;
    unsigned bits = 0;
    std::uint32_t bad = 0;  // OR of (code >= code_count): one test after the loop
    for (std::uint32_t k = 0; k + 2 < place.points; ++k) {
        while (bits < kPacked16CodeBits) acc |= std::uint64_t(*p++) << bits, bits += 8;
        const auto code = std::uint32_t(acc & kCodeMask);
        acc >>= kPacked16CodeBits, bits -= kPacked16CodeBits;
        bad |= code >= code_count;
        codes[2 * k] = std::uint8_t(code), codes[2 * k + 1] = std::uint8_t(code >> 8);
    }
    if (bad) return "a direction code past the " + std::to_string(levels) + " x " + std::to_string(levels) + " levels";
    if (acc != 0) return "non-zero padding bits after the last direction code";
    return {};
}

}  // namespace fiblet::detail
