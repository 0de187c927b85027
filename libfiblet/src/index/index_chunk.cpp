#include "index/index_chunk.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "core/bytes.hpp"
#include "fiblet/error.hpp"
#include "index/box_rans.hpp"
#include "index/box_stream.hpp"

namespace fiblet::detail {

IndexBoxDecoder::IndexBoxDecoder(const IndexGrid& g)
    : levels_(g.axis_levels()), e_(g.extent_levels), unbounded_(g.unbounded_code()) {
    const float o[3] = {g.origin.x, g.origin.y, g.origin.z};
    for (int a = 0; a < 3; ++a) {
        lo_[a].resize(levels_), hi_[a].resize(levels_);
        for (std::uint32_t c = 0; c < levels_; ++c) {
            const std::uint32_t i = c / e_, e = c % e_;
            lo_[a][c] = o[a] + float(i) * g.cell;
            hi_[a][c] = o[a] + float(i + e) * g.cell;
        }
    }
}

namespace {

// Per-fiber point counts of the last blocks, appended: 1 or 2 bytes a fiber
// (parse_last_points reads them).
void append_last_points(const IndexChunk& c, const FftHeader& h, std::vector<std::uint8_t>& out) {
    const unsigned count_bytes = index_count_bytes(h);
    for (const std::uint16_t n : c.last_block_points) {
        out.push_back(std::uint8_t(n));
        if (count_bytes == 2) out.push_back(std::uint8_t(n >> 8));
    }
}

}  // namespace

std::vector<std::uint8_t> serialize_index_chunk(const IndexChunk& c, const FftHeader& h,
                                                const std::vector<std::uint8_t>& box_stream) {
    // Fixed header, at the offsets parse_index_chunk reads.
    std::vector<std::uint8_t> out(kIndexChunkHeaderBytes, 0);
    auto put = [&](std::size_t at, auto v) { std::memcpy(&out[at], &v, sizeof v); };
    put(0, kIndexChunkVersion);
    put(8, c.fibers);
    put(16, c.blocks);
    put(24, c.grid.origin.x), put(28, c.grid.origin.y), put(32, c.grid.origin.z);
    put(36, c.grid.cell);
    put(40, c.grid.min_levels);
    put(44, c.max_sphere_radius);
    put(48, c.max_join);
    put(56, std::uint64_t(box_stream.size()));
    append_last_points(c, h, out);
    out.insert(out.end(), box_stream.begin(), box_stream.end());
    return out;
}

std::vector<std::uint8_t> serialize_index_chunk_v2(const IndexChunk& c, const FftHeader& h) {
    const unsigned bits = c.grid.bits;
    // Fixed header, at the offsets parse_v1_v2 reads.
    std::vector<std::uint8_t> out(kIndexChunkV2HeaderBytes, 0);
    auto put = [&](std::size_t at, auto v) { std::memcpy(&out[at], &v, sizeof v); };
    put(0, kIndexChunkV2Version);
    put(4, std::uint32_t(bits));
    put(8, c.fibers);
    put(16, c.blocks);
    put(24, c.grid.origin.x), put(28, c.grid.origin.y), put(32, c.grid.origin.z);
    put(36, c.grid.cell);
    put(40, c.grid.min_levels);
    put(44, c.grid.extent_levels);
    put(48, c.max_sphere_radius);
    put(52, c.group_blocks);
    put(56, c.groups);
    put(64, c.max_join);
    append_last_points(c, h, out);
    // Codes as one little-endian bit stream, least significant bit first.
    std::uint64_t acc = 0;
    unsigned filled = 0;
    for (std::uint32_t code : c.codes) {
        acc |= std::uint64_t(code) << filled;
        filled += bits;
        while (filled >= 8) out.push_back(std::uint8_t(acc)), acc >>= 8, filled -= 8;
    }
    if (filled > 0) out.push_back(std::uint8_t(acc));
    return out;
}

namespace {

[[noreturn]] void malformed(const std::string& file, const std::string& what) {
    throw Error(Errc::fft_format, file + ": malformed BIDX (block index) chunk: " + what);
}

// Per-fiber point counts of the last blocks, at `at`: 1 or 2 bytes a fiber.
void parse_last_points(const std::uint8_t* at, IndexChunk& c, const FftHeader& h, const std::string& file) {
    const unsigned count_bytes = index_count_bytes(h);
    c.last_block_points.resize(c.fibers);
    for (std::uint64_t f = 0; f < c.fibers; ++f) {
        const std::uint16_t n = count_bytes == 1 ? at[f] : std::uint16_t(at[2 * f] | at[2 * f + 1] << 8);
        if (n > h.points_per_block) malformed(file, "a fiber's last block holds more points than a block can");
        c.last_block_points[f] = n;
    }
}

void check_common(const IndexChunk& c, const FftHeader& h, const std::string& file) {
    if (c.fibers != h.fibers || c.blocks != h.blocks)
        malformed(file, "its fiber or block count differs from the header's");
    if (!(std::isfinite(c.grid.origin.x) && std::isfinite(c.grid.origin.y) && std::isfinite(c.grid.origin.z)))
        malformed(file, "grid origin is not finite");
    if (!(std::isfinite(c.grid.cell) && c.grid.cell > 0)) malformed(file, "grid cell is not a positive number");
    if (!(std::isfinite(c.max_sphere_radius) && c.max_sphere_radius >= 0)) malformed(file, "invalid sphere radius");
    if (c.version != 1 && !(std::isfinite(c.max_join) && c.max_join >= 0))
        malformed(file, "invalid block join distance");
}

// Version 3: a coded box per block.
// Versions 3 and 4: the same fields, a box stream each codes its own way.
IndexChunk parse_block_boxes(const std::vector<std::uint8_t>& p, const FftHeader& h, const std::string& file,
                             std::uint32_t version) {
    if (p.size() < kIndexChunkHeaderBytes) malformed(file, "truncated header");
    const std::uint8_t* b = p.data();
    IndexChunk c;
    c.version = version;
    c.fibers = get_le<std::uint64_t>(b + 8);
    c.blocks = c.groups = get_le<std::uint64_t>(b + 16);
    c.grid.origin = {get_le<float>(b + 24), get_le<float>(b + 28), get_le<float>(b + 32)};
    c.grid.cell = get_le<float>(b + 36);
    c.grid.min_levels = get_le<std::uint32_t>(b + 40);
    c.grid.extent_levels = kMaxBoxExtent + 1;
    c.max_sphere_radius = get_le<float>(b + 44);
    c.max_join = get_le<float>(b + 48);
    const std::uint64_t stream_bytes = get_le<std::uint64_t>(b + 56);
    if (get_le<std::uint32_t>(b + 4) != 0 || get_le<std::uint32_t>(b + 52) != 0)
        malformed(file, "reserved fields are not 0");
    check_common(c, h, file);
    if (c.grid.min_levels == 0 || c.grid.min_levels > kMaxGridLevels)
        malformed(file, "grid levels outside [1, 1024]");
    const std::uint64_t count_bytes = index_count_bytes(h);
    if (stream_bytes > p.size() || p.size() - stream_bytes != kIndexChunkHeaderBytes + count_bytes * c.fibers)
        malformed(file, "payload size does not match its counts");
    parse_last_points(b + kIndexChunkHeaderBytes, c, h, file);
    c.box_stream_offset = kIndexChunkHeaderBytes + count_bytes * c.fibers;
    c.box_stream_bytes = stream_bytes;
    return c;
}

// Versions 1 and 2: a fixed-width code per group (per block in version 1).
IndexChunk parse_v1_v2(const std::vector<std::uint8_t>& p, const FftHeader& h, const std::string& file,
                       std::uint32_t version) {
    const std::size_t header_bytes = version == 1 ? kIndexChunkV1HeaderBytes : kIndexChunkV2HeaderBytes;
    if (p.size() < header_bytes) malformed(file, "truncated header");
    IndexChunk c;
    const std::uint8_t* b = p.data();
    c.version = version;
    c.grid.bits = get_le<std::uint32_t>(b + 4);
    c.fibers = get_le<std::uint64_t>(b + 8);
    c.blocks = get_le<std::uint64_t>(b + 16);
    c.grid.origin = {get_le<float>(b + 24), get_le<float>(b + 28), get_le<float>(b + 32)};
    c.grid.cell = get_le<float>(b + 36);
    c.grid.min_levels = get_le<std::uint32_t>(b + 40);
    c.grid.extent_levels = get_le<std::uint32_t>(b + 44);
    c.max_sphere_radius = get_le<float>(b + 48);
    // Version 1: one box per block.
    c.group_blocks = version == 1 ? 1 : get_le<std::uint32_t>(b + 52);
    c.groups = version == 1 ? c.blocks : get_le<std::uint64_t>(b + 56);
    c.max_join = version == 1 ? -1.0f : get_le<float>(b + 64);

    const unsigned bits = c.grid.bits;
    if (bits < 8 || bits > 32) malformed(file, "bits per block " + std::to_string(bits) + " outside [8, 32]");
    check_common(c, h, file);
    // Every group holds 1..G blocks: at least ceil(blocks / G) of them, at most one a block.
    if (c.group_blocks == 0) malformed(file, "0 blocks per group");
    if (c.groups > c.blocks || c.groups < (c.blocks + c.group_blocks - 1) / c.group_blocks)
        malformed(file, "its group count does not fit its block count");
    const std::uint64_t levels = std::uint64_t(c.grid.min_levels) * c.grid.extent_levels;
    if (c.grid.min_levels == 0 || c.grid.extent_levels == 0 || levels > 0xffffffffull ||
        levels * levels * levels > std::uint64_t(c.grid.unbounded_code()))
        malformed(file, "grid levels do not fit the code width");
    const std::uint64_t code_bytes = (c.groups * bits + 7) / 8;
    const unsigned count_bytes = index_count_bytes(h);
    if (p.size() != header_bytes + count_bytes * c.fibers + code_bytes)
        malformed(file, "payload size does not match its counts");
    parse_last_points(b + header_bytes, c, h, file);

    c.codes.resize(c.groups);
    const std::uint8_t* s = b + header_bytes + count_bytes * c.fibers;
    const std::uint64_t max_code = levels * levels * levels;
    const std::uint32_t mask = c.grid.unbounded_code();
    for (std::uint64_t k = 0; k < c.groups; ++k) {
        const std::uint64_t bit = k * bits, byte = bit / 8;
        std::uint64_t word = 0;
        std::memcpy(&word, s + byte, std::min<std::uint64_t>(8, code_bytes - byte));
        const auto code = std::uint32_t((word >> (bit % 8)) & mask);
        if (code != mask && code >= max_code) malformed(file, "box code out of range");
        c.codes[k] = code;
    }
    return c;
}

}  // namespace

std::vector<std::uint64_t> index_block_cells(const IndexChunk& c, const std::vector<std::uint8_t>& payload,
                                             const FftFile& file) {
    std::vector<bool> first_of_fiber(c.blocks, false);  // a bit a block, not 4 bytes a fiber
    for (std::uint64_t f = 0; f < c.fibers; ++f)
        if (file.block_count(f) > 0) first_of_fiber[file.first_block(f)] = true;
    const std::uint8_t* stream = payload.data() + c.box_stream_offset;
    const std::uint32_t levels = c.grid.min_levels;
    DecodedBoxes d = c.version == kIndexChunkV3Version ? decode_box_stream(stream, c.box_stream_bytes, first_of_fiber, levels)
                                                       : decode_box_rans(stream, c.box_stream_bytes, first_of_fiber, levels);
    if (!d.error.empty()) malformed(file.path(), d.error);
    return std::move(d.boxes);
}

std::vector<Aabb> index_block_boxes(const IndexChunk& c, const std::vector<std::uint8_t>& payload,
                                    const FftFile& file) {
    const std::vector<std::uint64_t> cells = index_block_cells(c, payload, file);
    std::vector<Aabb> boxes;
    boxes.reserve(cells.size());
    for (const std::uint64_t v : cells) boxes.push_back(c.grid.bounds(v));
    return boxes;
}

IndexChunk parse_index_chunk(const std::vector<std::uint8_t>& p, const FftHeader& h, const std::string& file) {
    if (p.size() < 4) malformed(file, "truncated header");
    const std::uint32_t version = get_le<std::uint32_t>(p.data());
    if (version == kIndexChunkVersion || version == kIndexChunkV3Version) return parse_block_boxes(p, h, file, version);
    if (version == 1 || version == 2) return parse_v1_v2(p, h, file, version);
    malformed(file, "unsupported version " + std::to_string(version));
}

}  // namespace fiblet::detail
