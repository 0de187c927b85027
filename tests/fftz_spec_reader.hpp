// A .fftz container unpacked to the .fft bytes it holds, written from
// formats/fftz.md alone (no library code): the seek table's frames
// decompressed with libzstd and concatenated, each block group's transposed
// fields (layout 1) put back into blocks. What an outside reader of the
// container would write; the float64 reference decoder (exact_decoder.hpp)
// then reads the result, so the conformance corpus's .fftz files get
// float64 points too (tests/tools/exact_points.cpp).
#pragma once

#include <zstd.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace fiblet::test::fftz_spec {

inline std::uint32_t u32(const std::string& b, std::size_t at) {
    if (at + 4 > b.size()) throw std::runtime_error("fftz: file too short");
    return std::uint32_t((unsigned char)b[at]) | std::uint32_t((unsigned char)b[at + 1]) << 8 |
           std::uint32_t((unsigned char)b[at + 2]) << 16 | std::uint32_t((unsigned char)b[at + 3]) << 24;
}

// "A reader recognizes a .fftz by its first 12 bytes: 50 2A 4D 18, any size, FFTZ".
inline bool is_fftz(const std::string& b) {
    return b.size() >= 12 && u32(b, 0) == 0x184D2A50u && b.compare(8, 4, "FFTZ") == 0;
}

struct Frame {
    std::uint32_t compressed, decompressed;
};

// The seek table at the file's end: its footer (frames, descriptor, magic),
// then one (compressed, decompressed) pair per frame before it.
inline std::vector<Frame> seek_table(const std::string& b) {
    if (b.size() < 9 || u32(b, b.size() - 4) != 0x8F92EAB1u) throw std::runtime_error("fftz: no seek table footer");
    const std::uint32_t frames = u32(b, b.size() - 9);
    if ((unsigned char)b[b.size() - 5] != 0) throw std::runtime_error("fftz: per-entry checksums are not written");
    const std::size_t entries = b.size() - 9 - 8 * std::size_t(frames);
    if (frames > b.size() / 8 || entries < 8 || u32(b, entries - 8) != 0x184D2A5Eu)
        throw std::runtime_error("fftz: bad seek table");
    std::vector<Frame> out(frames);
    for (std::uint32_t i = 0; i < frames; ++i) out[i] = {u32(b, entries + 8 * i), u32(b, entries + 8 * i + 4)};
    return out;
}

// One group of n blocks of `size` bytes from its transposed layout
// (formats/fftz.md "Transposed groups"); version 2 or 16.
inline std::string untranspose(const std::string& t, std::size_t n, std::size_t size, int version) {
    const bool wide = version == 16;
    const int value_bytes = wide ? 3 : 2, head = wide ? 18 : 12, rest = 6, codes_at = head + rest;
    if (t.size() != n * size) throw std::runtime_error("fftz: group of the wrong size");
    std::string out(n * size, '\0');
    std::size_t at = 0;
    // 1. Six anchor values per block, byte planes from the most significant;
    //    values 3..5 are anchor 1 minus anchor 0, modulo 2^(8 value_bytes).
    std::vector<std::uint32_t> values(6 * n, 0);
    for (int v = 0; v < 6; ++v)
        for (int byte = value_bytes - 1; byte >= 0; --byte)
            for (std::size_t j = 0; j < n; ++j) values[6 * j + v] |= std::uint32_t((unsigned char)t[at++]) << (8 * byte);
    const std::uint32_t mask = wide ? 0xffffffu : 0xffffu;
    for (std::size_t j = 0; j < n; ++j) {
        unsigned char* blk = reinterpret_cast<unsigned char*>(&out[j * size]);
        std::uint32_t a0[3], a1[3];
        for (int c = 0; c < 3; ++c) a0[c] = values[6 * j + c], a1[c] = (a0[c] + values[6 * j + 3 + c]) & mask;
        if (wide) {  // fft16.md: unorm24, least significant byte first, anchor 0 then anchor 1
            for (int c = 0; c < 3; ++c)
                for (int k = 0; k < 3; ++k) blk[3 * c + k] = (a0[c] >> (8 * k)) & 0xff, blk[9 + 3 * c + k] = (a1[c] >> (8 * k)) & 0xff;
        } else {  // fft.md §3: value 2w in word w's low half, 2w + 1 in its high half, most significant byte first
            const std::uint32_t v[6] = {a0[0], a0[1], a0[2], a1[0], a1[1], a1[2]};
            for (int w = 0; w < 3; ++w) {
                const std::uint32_t word = v[2 * w + 1] << 16 | v[2 * w];
                for (int k = 0; k < 4; ++k) blk[4 * w + k] = (word >> (24 - 8 * k)) & 0xff;
            }
        }
    }
    // 2. The rest of the block header, byte position by byte position.
    for (int k = 0; k < rest; ++k)
        for (std::size_t j = 0; j < n; ++j) out[j * size + head + k] = t[at++];
    // 3. The codes: version 2's code areas one after the other; version 16's
    //    u16 words, all high bytes, then all low bytes.
    const std::size_t area = size - codes_at;
    if (!wide) {
        for (std::size_t j = 0; j < n; ++j) std::memcpy(&out[j * size + codes_at], &t[at + j * area], area), void();
        return out;
    }
    const std::size_t words = area / 2;
    for (int half = 1; half >= 0; --half)
        for (std::size_t j = 0; j < n; ++j)
            for (std::size_t w = 0; w < words; ++w) out[j * size + codes_at + 2 * w + half] = t[at++];
    return out;
}

// The .fft bytes a .fftz holds.
inline std::string unpack(const std::string& b) {
    if (!is_fftz(b)) throw std::runtime_error("fftz: not a .fftz");
    if ((unsigned char)b[12] != 1) throw std::runtime_error("fftz: container version");
    const int layout = (unsigned char)b[13];
    const std::uint32_t group_blocks = u32(b, 16);
    const std::vector<Frame> frames = seek_table(b);
    std::vector<std::string> content;
    std::size_t at = 0;
    for (const Frame& f : frames) {
        if (at + f.compressed > b.size()) throw std::runtime_error("fftz: frame past the end");
        std::string out(f.decompressed, '\0');
        if (u32(b, at) >> 4 != 0x184D2A5u) {  // not a skippable frame
            const std::size_t n = ZSTD_decompress(out.data(), out.size(), b.data() + at, f.compressed);
            if (ZSTD_isError(n) || n != f.decompressed) throw std::runtime_error("fftz: frame does not decompress");
        }
        content.push_back(out);
        at += f.compressed;
    }
    // Frames: 0 descriptor, 1 header, 2 LUT, then the block groups, then
    // perhaps the trailer; the header says how many blocks and how large.
    if (content.size() < 3) throw std::runtime_error("fftz: fewer than three frames");
    const std::string& header = content[1];
    const int version = (unsigned char)header.at(0);
    const std::uint32_t blocks = u32(header, 17), points_per_block = u32(header, 21);
    const std::size_t size = version == 16 ? (24 + 2 * (std::size_t(points_per_block) - 2) + 3) / 4 * 4
                                           : (std::size_t(points_per_block) + 16 + 3) / 4 * 4;
    const std::size_t groups = (std::size_t(blocks) + group_blocks - 1) / group_blocks;
    if (content.size() < 3 + groups) throw std::runtime_error("fftz: missing block groups");
    std::string fft = header + content[2];
    for (std::size_t g = 0; g < groups; ++g) {
        const std::size_t n = std::min<std::size_t>(group_blocks, blocks - g * group_blocks);
        fft += layout == 1 ? untranspose(content[3 + g], n, size, version) : content[3 + g];
    }
    for (std::size_t i = 3 + groups; i < content.size(); ++i) fft += content[i];
    return fft;
}

}  // namespace fiblet::test::fftz_spec
