// Field-by-field form of a group of blocks (formats/fftz.md, layout 1):
// each field's bytes end up next to the same field of the other blocks, and
// anchor 1 becomes a small difference to anchor 0, which zstd compresses
// far better than whole 76-byte records.
#include <algorithm>
#include <array>
#include <string>

#include "fiblet/error.hpp"
#include "fiblet/fft_format.hpp"
#include "fiblet/fftz_format.hpp"

namespace fiblet {

namespace {

// Where the fields of a block lie, for either layout.
struct BlockFields {
    unsigned value_bytes;   // bytes per anchor value: 2 (unorm16) or 3 (unorm24)
    std::size_t head_end;   // end of the header (anchors + fiber id + flags ...)
    std::size_t rest_begin; // first header byte after the anchors
    bool wide_codes;
};

BlockFields fields_of(unsigned direction_bits, std::uint32_t block_bytes) {
    if (direction_bits == 16) {
        if (block_bytes < kBlock16DirectionsOffset || (block_bytes - kBlock16DirectionsOffset) % 2 != 0)
            throw Error(Errc::invalid_argument, "bad 16-bit block size " + std::to_string(block_bytes));
        return {3, kBlock16DirectionsOffset, 18, true};
    }
    if (block_bytes < kBlockDirectionsOffset)
        throw Error(Errc::invalid_argument, "bad block size " + std::to_string(block_bytes));
    return {2, kBlockDirectionsOffset, kBlockAnchorBytes, false};
}

// The six anchor values (x0 y0 z0 x1 y1 z1) of a block.
std::array<std::uint32_t, 6> read_anchors(const std::uint8_t* b, unsigned value_bytes) {
    std::array<std::uint32_t, 6> q{};
    if (value_bytes == 3) {
        for (int i = 0; i < 6; ++i) q[i] = b[3 * i] | b[3 * i + 1] << 8 | std::uint32_t(b[3 * i + 2]) << 16;
    } else {
        // Version 2: word k holds the pair (q[2k], q[2k+1]) as q[2k] | q[2k+1] << 16, most-significant byte first.
        for (int k = 0; k < 3; ++k) {
            q[2 * k] = std::uint32_t(b[4 * k + 2] << 8 | b[4 * k + 3]);
            q[2 * k + 1] = std::uint32_t(b[4 * k] << 8 | b[4 * k + 1]);
        }
    }
    return q;
}

void write_anchors(std::uint8_t* b, const std::array<std::uint32_t, 6>& q, unsigned value_bytes) {
    if (value_bytes == 3) {
        for (int i = 0; i < 6; ++i)
            b[3 * i] = std::uint8_t(q[i]), b[3 * i + 1] = std::uint8_t(q[i] >> 8), b[3 * i + 2] = std::uint8_t(q[i] >> 16);
    } else {
        for (int k = 0; k < 3; ++k) {
            b[4 * k] = std::uint8_t(q[2 * k + 1] >> 8), b[4 * k + 1] = std::uint8_t(q[2 * k + 1]);
            b[4 * k + 2] = std::uint8_t(q[2 * k] >> 8), b[4 * k + 3] = std::uint8_t(q[2 * k]);
        }
    }
}

// Step 1 of untranspose_block_group for n blocks: the anchors from their
// byte planes at `in` into each block of `out` (bb bytes apart). The value
// width as a constant, so that the planes' loops unroll: decoding a .fftz
// spends as much here as in the rest of the untransposing.
template <unsigned kValueBytes>
void untranspose_anchors(const std::uint8_t* in, std::size_t n, std::uint32_t bb, std::uint8_t* out) {
    constexpr std::uint32_t kMask = kValueBytes == 3 ? 0xffffffu : 0xffffu;
    for (std::size_t b = 0; b < n; ++b) {
        std::array<std::uint32_t, 6> q{};
        for (int v = 0; v < 6; ++v)
            for (unsigned k = 0; k < kValueBytes; ++k) q[v] = q[v] << 8 | in[(std::size_t(v) * kValueBytes + k) * n + b];
        for (int i = 0; i < 3; ++i) q[3 + i] = (q[3 + i] + q[i]) & kMask;
        write_anchors(&out[b * bb], q, kValueBytes);
    }
}

std::size_t group_count(std::size_t bytes, std::uint32_t block_bytes) {
    if (block_bytes == 0 || bytes % block_bytes != 0)
        throw Error(Errc::fft_format, "block group of " + std::to_string(bytes) + " bytes is not a whole number of " +
                                          std::to_string(block_bytes) + "-byte blocks");
    return bytes / block_bytes;
}

}  // namespace

std::vector<std::uint8_t> transpose_block_group(std::span<const std::uint8_t> blocks, unsigned direction_bits,
                                                std::uint32_t bb) {
    const BlockFields f = fields_of(direction_bits, bb);
    const std::size_t n = group_count(blocks.size(), bb);
    const std::uint32_t mask = f.value_bytes == 3 ? 0xffffffu : 0xffffu;
    std::vector<std::uint8_t> out(blocks.size());
    std::uint8_t* o = out.data();
    // 1. Anchors, anchor 1 as a difference, byte planes from the most significant.
    for (std::size_t b = 0; b < n; ++b) {
        auto q = read_anchors(&blocks[b * bb], f.value_bytes);
        for (int i = 0; i < 3; ++i) q[3 + i] = (q[3 + i] - q[i]) & mask;
        for (int v = 0; v < 6; ++v)
            for (unsigned k = 0; k < f.value_bytes; ++k)
                o[(std::size_t(v) * f.value_bytes + k) * n + b] = std::uint8_t(q[v] >> (8 * (f.value_bytes - 1 - k)));
    }
    o += 6 * f.value_bytes * n;
    // 2. The rest of the header, byte planes.
    for (std::size_t k = f.rest_begin; k < f.head_end; ++k)
        for (std::size_t b = 0; b < n; ++b) *o++ = blocks[b * bb + k];
    // 3. Codes.
    const std::size_t code_bytes = bb - f.head_end;
    if (!f.wide_codes) {
        for (std::size_t b = 0; b < n; ++b, o += code_bytes)
            std::copy_n(&blocks[b * bb + f.head_end], code_bytes, o);
    } else {
        const std::size_t words = code_bytes / 2, plane = n * words;
        for (std::size_t b = 0; b < n; ++b)
            for (std::size_t w = 0; w < words; ++w) {
                o[b * words + w] = blocks[b * bb + f.head_end + 2 * w + 1];       // high bytes
                o[plane + b * words + w] = blocks[b * bb + f.head_end + 2 * w];  // low bytes
            }
    }
    return out;
}

std::vector<std::uint8_t> untranspose_block_group(std::span<const std::uint8_t> fields, unsigned direction_bits,
                                                  std::uint32_t bb) {
    std::vector<std::uint8_t> out(fields.size());
    untranspose_block_group(fields, direction_bits, bb, out);
    return out;
}

void untranspose_block_group(std::span<const std::uint8_t> fields, unsigned direction_bits, std::uint32_t bb,
                             std::span<std::uint8_t> out) {
    if (out.size() != fields.size())
        throw Error(Errc::invalid_argument, "untranspose_block_group: " + std::to_string(out.size()) +
                                                " bytes for a group of " + std::to_string(fields.size()));
    const BlockFields f = fields_of(direction_bits, bb);
    const std::size_t n = group_count(fields.size(), bb);
    const std::uint8_t* in = fields.data();
    if (f.value_bytes == 3) untranspose_anchors<3>(in, n, bb, out.data());
    else untranspose_anchors<2>(in, n, bb, out.data());
    in += 6 * f.value_bytes * n;
    for (std::size_t k = f.rest_begin; k < f.head_end; ++k)
        for (std::size_t b = 0; b < n; ++b) out[b * bb + k] = *in++;
    const std::size_t code_bytes = bb - f.head_end;
    if (!f.wide_codes) {
        for (std::size_t b = 0; b < n; ++b, in += code_bytes) std::copy_n(in, code_bytes, &out[b * bb + f.head_end]);
    } else {
        const std::size_t words = code_bytes / 2, plane = n * words;
        for (std::size_t b = 0; b < n; ++b)
            for (std::size_t w = 0; w < words; ++w) {
                out[b * bb + f.head_end + 2 * w + 1] = in[b * words + w];
                out[b * bb + f.head_end + 2 * w] = in[plane + b * words + w];
            }
    }
}

}  // namespace fiblet
