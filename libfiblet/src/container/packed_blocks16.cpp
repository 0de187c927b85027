#include "container/packed_blocks16.hpp"

#include <algorithm>
#include <cstring>

#include "core/points_avx2.hpp"

namespace fiblet::detail {

namespace {

constexpr std::uint32_t kCodeMask = (1u << kPacked16CodeBits) - 1;

std::uint16_t get_u16(const std::uint8_t* p) { return std::uint16_t(p[0] | p[1] << 8); }

#ifdef FIBLET_POINTS_AVX2
// Eight codes from the 15 bytes at p (read as 16), one per 32-bit lane:
// each lane takes the three bytes holding its code (codes 0-3 from the
// low half of the load, 4-7 from both), shifted down and masked.
__attribute__((target("avx2"))) inline __m256i eight_codes_avx2(const std::uint8_t* p) {
    // Code j starts at bit 15 j: byte 15 j / 8, bit 15 j % 8.
    const __m256i bytes = _mm256_broadcastsi128_si256(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
    const __m256i pick = _mm256_setr_epi8(0, 1, 2, -1, 1, 2, 3, -1, 3, 4, 5, -1, 5, 6, 7, -1,    //
                                          7, 8, 9, -1, 9, 10, 11, -1, 11, 12, 13, -1, 13, 14, 15, -1);
    const __m256i shift = _mm256_setr_epi32(0, 7, 6, 5, 4, 3, 2, 1);
    return _mm256_and_si256(_mm256_srlv_epi32(_mm256_shuffle_epi8(bytes, pick), shift),
                            _mm256_set1_epi32(int(kCodeMask)));
}

// expand_block16's first loop sixteen codes at a time, from codes k while
// 31 bytes from their first stay inside the block: the same codes into
// `codes`, the largest into `largest`; returns where it stopped.
__attribute__((target("avx2"))) std::uint32_t expand_codes_avx2(const std::uint8_t* p, std::size_t code_bytes,
                                                                std::uint32_t m, std::uint8_t* codes,
                                                                std::uint16_t& largest) {
    __m256i top = _mm256_setzero_si256();
    std::uint32_t k = 0;
    for (; k + 16 <= m && std::size_t(15) * (k / 8) + 31 <= code_bytes; k += 16) {
        const std::uint8_t* at = p + 15 * (k / 8);
        // packus interleaves the halves: codes 0-3, 8-11, 4-7, 12-15, put back in order.
        const __m256i sixteen = _mm256_permute4x64_epi64(
            _mm256_packus_epi32(eight_codes_avx2(at), eight_codes_avx2(at + 15)), 0b11011000);
        top = _mm256_max_epu16(top, sixteen);
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(codes + 2 * k), sixteen);
    }
    alignas(32) std::uint16_t lanes[16];
    _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), top);
    for (const std::uint16_t c : lanes) largest = std::max(largest, c);
    return k;
}
#endif

}  // namespace

void pack_blocks16(const FftHeader& h, std::span<const std::uint8_t> blocks, std::vector<std::uint8_t>& out,
                   std::vector<std::uint32_t>* sizes) {
    const std::size_t bb = h.block_bytes();
    for (std::size_t at = 0; at + bb <= blocks.size(); at += bb) {
        const std::uint8_t* b = blocks.data() + at;
        const std::uint32_t n = get_u16(b + kBlock16FlagsOffset) & kFlag16CountMask;
        const std::size_t start = out.size();
        out.resize(start + packed16_block_bytes(n));
        if (sizes) sizes->push_back(packed16_block_bytes(n));
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
    const std::uint32_t m = place.points > 2 ? place.points - 2 : 0;  // codes
    const std::size_t code_bytes = (std::size_t{kPacked16CodeBits} * m + 7) / 8;
    std::memcpy(out, packed, kPacked16AnchorBytes);
    const std::uint32_t id = place.fiber_id;
    std::memcpy(out + kBlock16FiberIdOffset, &id, 4);  // hosts are little-endian (checked in CMake)
    const std::uint16_t flags = std::uint16_t((place.first ? 0u : kFlag16NotFirst) | (place.last ? 0u : kFlag16NotLast) |
                                              place.points);
    std::memcpy(out + kBlock16FlagsOffset, &flags, 2);
    std::uint8_t* codes = out + kBlock16DirectionsOffset;
    std::memset(codes + 2 * std::size_t(m), 0, h.block_bytes() - kBlock16DirectionsOffset - 2 * std::size_t(m));
    const std::uint8_t* p = packed + kPacked16AnchorBytes;
    const std::uint32_t levels = h.code_levels(), code_count = levels * levels;
    std::uint32_t bad = 0;  // OR of (code >= code_count): one test after the loops
    std::uint32_t k = 0;
    static_assert(kPacked16CodeBits == 15);
#ifdef FIBLET_POINTS_AVX2
    if (use_avx2_loops()) {
        std::uint16_t largest = 0;
        k = expand_codes_avx2(p, code_bytes, m, codes, largest);
        bad |= largest >= code_count;
    }
#endif
    // Eight codes from each 15 bytes (codes 8j.. start on byte 15j), read as
    // two little-endian words while 16 bytes stay inside the block...
    for (; k + 8 <= m && std::size_t(15) * (k / 8) + 16 <= code_bytes; k += 8) {
        std::uint64_t lo, hi;
        std::memcpy(&lo, p + 15 * (k / 8), 8);
        std::memcpy(&hi, p + 15 * (k / 8) + 8, 8);
        const std::uint16_t eight[8] = {std::uint16_t(lo & kCodeMask),
                                        std::uint16_t(lo >> 15 & kCodeMask),
                                        std::uint16_t(lo >> 30 & kCodeMask),
                                        std::uint16_t(lo >> 45 & kCodeMask),
                                        std::uint16_t((lo >> 60 | hi << 4) & kCodeMask),  // bits 60..74
                                        std::uint16_t(hi >> 11 & kCodeMask),
                                        std::uint16_t(hi >> 26 & kCodeMask),
                                        std::uint16_t(hi >> 41 & kCodeMask)};
        std::uint16_t largest = 0;
        for (const std::uint16_t c : eight) largest = std::max(largest, c);
        bad |= largest >= code_count;
        std::memcpy(codes + 2 * k, eight, sizeof eight);
    }
    // ...then one unaligned 8-byte load a code while it stays inside...
    for (; k < m && std::size_t(kPacked16CodeBits) * k / 8 + 8 <= code_bytes; ++k) {
        const std::size_t bit = std::size_t(kPacked16CodeBits) * k;
        std::uint64_t w;
        std::memcpy(&w, p + bit / 8, 8);
        const auto code = std::uint16_t((w >> (bit % 8)) & kCodeMask);
        bad |= code >= code_count;
        std::memcpy(codes + 2 * k, &code, 2);
    }
    // ...then byte by byte for the last few.
    for (; k < m; ++k) {
        const std::size_t bit = std::size_t(kPacked16CodeBits) * k;
        std::uint32_t w = 0;
        for (std::size_t j = bit / 8, s = 0; j < code_bytes && s < 24; ++j, s += 8) w |= std::uint32_t(p[j]) << s;
        const auto code = std::uint16_t((w >> (bit % 8)) & kCodeMask);
        bad |= code >= code_count;
        std::memcpy(codes + 2 * k, &code, 2);
    }
    if (bad) return "a direction code past the " + std::to_string(levels) + " x " + std::to_string(levels) + " levels";
    if (const unsigned used = (kPacked16CodeBits * m) % 8; used != 0 && (p[code_bytes - 1] >> used) != 0)
        return "non-zero padding bits after the last direction code";
    return {};
}

}  // namespace fiblet::detail
