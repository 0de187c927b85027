// Structure-aware mutations of .fft files and .fftz containers for
// libFuzzer's custom mutator: the damage that byte-level mutation rarely
// composes (a chunk tag or size changed, a footer damaged, a chunk
// duplicated or dropped, the file cut or extended, blocks swapped, a seek
// table entry or a frame's bytes edited). Each mutation keeps the rest of
// the file intact, so that the reader's trailer and container checks are
// what the input exercises.
#pragma once

#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace fiblet::fuzz {

namespace detail {

template <class T>
inline T peek(const std::string& b, std::size_t at) {
    T v{};
    if (at + sizeof(T) <= b.size()) std::memcpy(&v, b.data() + at, sizeof(T));
    return v;
}
template <class T>
inline void poke(std::string& b, std::size_t at, T v) {
    if (at + sizeof(T) <= b.size()) std::memcpy(b.data() + at, &v, sizeof(T));
}

struct ChunkSpan {
    std::size_t at, size;  // whole chunk: 16-byte head + payload
};

// The plain file's end of blocks and its trailer chunks, as far as they parse.
inline std::size_t blocks_end(const std::string& b) {
    if (b.size() < 58) return b.size();
    const std::uint64_t fibers = peek<std::uint64_t>(b, 1), blocks = peek<std::uint32_t>(b, 17);
    const std::uint32_t ppb = peek<std::uint32_t>(b, 21);
    const std::uint64_t block_bytes = b[0] == 16 ? (24 + 2 * std::uint64_t(ppb) + 3) / 4 * 4 : (ppb + 16 + 3) / 4 * 4;
    const std::uint64_t end = 58 + 8 * std::uint64_t(std::uint8_t(b[57])) + 8 * fibers + blocks * block_bytes;
    return end <= b.size() ? std::size_t(end) : b.size();
}

inline std::vector<ChunkSpan> chunks(const std::string& b, std::size_t end) {
    std::vector<ChunkSpan> out;
    for (std::size_t pos = end; b.size() >= 16 && pos + 16 <= b.size() - 16;) {
        const std::uint64_t size = peek<std::uint64_t>(b, pos + 8);
        if (size > b.size() - 16 - pos - 16) break;
        out.push_back({pos, std::size_t(16 + size)});
        pos += std::size_t(16 + size);
    }
    return out;
}

inline bool is_fftz(const std::string& b) { return b.size() >= 12 && std::memcmp(b.data() + 8, "FFTZ", 4) == 0; }

inline void mutate_fft(std::string& b, std::minstd_rand& rng) {
    auto pick = [&](std::size_t n) { return std::size_t(rng() % (n ? n : 1)); };
    const std::size_t end = blocks_end(b);
    const std::vector<ChunkSpan> cs = chunks(b, end);
    const ChunkSpan c = cs.empty() ? ChunkSpan{end, 0} : cs[pick(cs.size())];
    switch (rng() % 9) {
        case 0:  // a bit of a chunk tag
            if (c.size) b[c.at + pick(4)] ^= char(1u << pick(8));
            break;
        case 1:  // a chunk size: off by a little, or any value
            if (c.size) poke<std::uint64_t>(b, c.at + 8, rng() % 2 ? c.size - 16 + (rng() % 17) - 8 : rng());
            break;
        case 2:  // the footer: a bit anywhere in its 16 bytes
            if (b.size() >= 16) b[b.size() - 16 + pick(16)] ^= char(1u << pick(8));
            break;
        case 3:  // cut the file
            b.resize(b.size() - std::min(b.size(), 1 + pick(64)));
            break;
        case 4:  // extend it: zeros, or a copy of its own tail
            b += rng() % 2 ? std::string(1 + pick(4096), '\0') : b.substr(b.size() - std::min<std::size_t>(b.size(), 16));
            break;
        case 5:  // a chunk twice
            if (c.size) b.insert(c.at, b.substr(c.at, c.size));
            break;
        case 6:  // a chunk dropped
            if (c.size) b.erase(c.at, c.size);
            break;
        case 7: {  // two blocks swapped (same size: the layout holds)
            const std::uint32_t ppb = peek<std::uint32_t>(b, 21), blocks = peek<std::uint32_t>(b, 17);
            const std::size_t bb = b[0] == 16 ? (24 + 2 * std::size_t(ppb) + 3) / 4 * 4 : (ppb + 16 + 3) / 4 * 4;
            // Only blocks that are really there (a mutated header may claim more).
            const std::size_t present = bb ? std::min<std::size_t>(blocks, end / bb) : 0;
            const std::size_t first = end - present * bb;
            if (present >= 2) {
                const std::size_t x = first + pick(present) * bb, y = first + pick(present) * bb;
                const std::string tmp = b.substr(x, bb);
                b.replace(x, bb, b.substr(y, bb));
                b.replace(y, bb, tmp);
            }
            break;
        }
        default:  // a payload byte of a chunk
            if (c.size > 16) b[c.at + 16 + pick(c.size - 16)] ^= char(1u << pick(8));
    }
}

inline void mutate_fftz(std::string& b, std::minstd_rand& rng) {
    auto pick = [&](std::size_t n) { return std::size_t(rng() % (n ? n : 1)); };
    if (b.size() < 17) return;
    const std::uint32_t frames = peek<std::uint32_t>(b, b.size() - 9);
    const std::size_t entries = b.size() - 9 - std::min<std::size_t>(b.size() - 9, 8 * std::size_t(frames));
    switch (rng() % 5) {
        case 0:  // a seek table entry: compressed or decompressed size
            if (frames) poke<std::uint32_t>(b, entries + 8 * pick(frames) + 4 * pick(2), std::uint32_t(rng()));
            break;
        case 1:  // a bit inside a frame's stored bytes
            b[pick(entries)] ^= char(1u << pick(8));
            break;
        case 2:  // the seek table's footer or frame header
            b[b.size() - 1 - pick(std::min<std::size_t>(b.size(), 17 + 8 * std::size_t(frames)))] ^= char(1u << pick(8));
            break;
        case 3:  // cut or extend
            if (rng() % 2) b.resize(b.size() - std::min(b.size(), 1 + pick(64)));
            else b += std::string(1 + pick(4096), '\0');
            break;
        default: {  // a decompressed size claimed far larger than the frame holds
            if (frames > 2) poke<std::uint32_t>(b, entries + 8 * (1 + pick(frames - 1)) + 4, 1u << (20 + pick(11)));
        }
    }
}

}  // namespace detail

// Mutates `b` in place; returns false when it left it unchanged.
inline bool mutate_structure(std::string& b, unsigned seed) {
    std::minstd_rand rng(seed);
    const std::string before = b;
    if (detail::is_fftz(b)) detail::mutate_fftz(b, rng);
    else detail::mutate_fft(b, rng);
    return b != before;
}

}  // namespace fiblet::fuzz
