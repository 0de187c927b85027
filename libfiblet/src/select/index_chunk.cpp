#include "select/index_chunk.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "core/bytes.hpp"
#include "fiblet/error.hpp"

namespace fiblet::detail {

namespace {

// Slack, in cells, between a box and its quantized bounds: far above the
// float rounding of origin + i * cell, far below a cell.
constexpr double kSlackCells = 1e-3;
// Margin of the grid around the normalized cube, in normalized units:
// decoded points may stray a few micrometres outside it (about 1e-4).
constexpr double kCubeMargin = 1.0 / 1024;

// Largest v with v^3 < 2^bits - 1 (so that the all-ones code stays free).
std::uint32_t max_axis_levels(unsigned bits) {
    const std::uint64_t limit = (std::uint64_t{1} << bits) - 1;
    std::uint64_t v = std::uint64_t(std::cbrt(double(limit))) + 2;
    while (v * v * v >= limit) --v;
    return std::uint32_t(v);
}

}  // namespace

IndexGrid IndexGrid::for_header(const FftHeader& h, unsigned bits, std::uint32_t group_blocks) {
    IndexGrid g;
    g.bits = bits;
    const float lo = float(-kCubeMargin);
    g.origin = h.to_world(lo, lo, lo);
    const double range = double(h.scaling) * (1 + 2 * kCubeMargin);
    // A group of G blocks spans at most G*n-1 steps plus the quantization of
    // its first block's second anchor; one more step of room keeps every
    // group fiblet writes on the grid (larger ones are stored as unbounded,
    // never wrongly culled).
    const double extent = double(group_blocks) * double(h.points_per_block) * double(h.step) * double(h.scaling);
    const std::uint32_t v = max_axis_levels(bits);
    // A box of extent x spans i..j with j - i < x / cell + 2 + 2 * slack
    // (floor below, ceil above), so e < extent_levels needs
    // extent <= (extent_levels - 2 - 2 * slack) * cell.
    auto smallest_cell = [&](double box_extent) {
        double best = std::numeric_limits<double>::infinity();
        for (std::uint32_t e = 3; e <= v / 2; ++e) {
            const std::uint32_t n = v / e;
            const double cell = std::max(box_extent / (double(e) - 2 - 2 * kSlackCells), range / double(n - 1));
            if (cell < best) best = cell, g.extent_levels = e, g.min_levels = n;
        }
        return best;
    };
    double best = smallest_cell(extent);
    // Coordinates near the float range (a step of 1e38 mm): that cell is no
    // float. No box spans more than the range, so size the cell for that.
    if (!(float(best) < std::numeric_limits<float>::infinity())) best = smallest_cell(std::min(extent, range));
    // Round the cell up to a float, then make sure the grid still covers the range.
    g.cell = std::nextafter(float(best), std::numeric_limits<float>::infinity());
    return g;
}

std::uint32_t IndexGrid::encode(const Aabb& box) const {
    std::uint32_t code = 0, scale = 1;
    const float lo[3] = {box.min.x, box.min.y, box.min.z}, hi[3] = {box.max.x, box.max.y, box.max.z};
    const float o[3] = {origin.x, origin.y, origin.z};
    for (int a = 0; a < 3; ++a) {
        const double b = (double(lo[a]) - o[a]) / cell - kSlackCells;
        const double t = (double(hi[a]) - o[a]) / cell + kSlackCells;
        if (!(b >= 0 && t >= b && t < double(min_levels + extent_levels))) return unbounded_code();
        const auto i = std::uint32_t(std::floor(b));
        const auto j = std::uint32_t(std::ceil(t));
        if (i >= min_levels || j - i >= extent_levels) return unbounded_code();
        code += (i * extent_levels + (j - i)) * scale;
        scale *= axis_levels();
    }
    return code;
}

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

std::vector<std::uint8_t> serialize_index_chunk(const IndexChunk& c, const FftHeader& h) {
    const unsigned bits = c.grid.bits;
    // Fixed header, at the offsets parse_index_chunk reads.
    std::vector<std::uint8_t> out(kIndexChunkHeaderBytes, 0);
    auto put = [&](std::size_t at, auto v) { std::memcpy(&out[at], &v, sizeof v); };
    put(0, kIndexChunkVersion);
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
    const unsigned count_bytes = index_count_bytes(h);
    out.resize(kIndexChunkHeaderBytes + count_bytes * c.last_block_points.size());
    for (std::size_t f = 0; f < c.last_block_points.size(); ++f) {
        const std::uint16_t n = c.last_block_points[f];
        out[kIndexChunkHeaderBytes + count_bytes * f] = std::uint8_t(n);
        if (count_bytes == 2) out[kIndexChunkHeaderBytes + 2 * f + 1] = std::uint8_t(n >> 8);
    }
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

IndexChunk parse_index_chunk(const std::vector<std::uint8_t>& p, const FftHeader& h, const std::string& file) {
    auto bad = [&](const std::string& what) -> IndexChunk {
        throw Error(Errc::fft_format, file + ": malformed BIDX (block index) chunk: " + what);
    };
    if (p.size() < 4) return bad("truncated header");
    IndexChunk c;
    const std::uint8_t* b = p.data();
    const std::uint32_t version = get_le<std::uint32_t>(b);
    if (version != 1 && version != kIndexChunkVersion) return bad("unsupported version " + std::to_string(version));
    const std::size_t header_bytes = version == 1 ? kIndexChunkV1HeaderBytes : kIndexChunkHeaderBytes;
    if (p.size() < header_bytes) return bad("truncated header");
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
    if (bits < 8 || bits > 32) return bad("bits per block " + std::to_string(bits) + " outside [8, 32]");
    if (c.fibers != h.fibers || c.blocks != h.blocks) return bad("its fiber or block count differs from the header's");
    // Every group holds 1..G blocks: at least ceil(blocks / G) of them, at most one a block.
    if (c.group_blocks == 0) return bad("0 blocks per group");
    if (c.groups > c.blocks || c.groups < (c.blocks + c.group_blocks - 1) / c.group_blocks)
        return bad("its group count does not fit its block count");
    if (!(std::isfinite(c.grid.origin.x) && std::isfinite(c.grid.origin.y) && std::isfinite(c.grid.origin.z)))
        return bad("grid origin is not finite");
    if (!(std::isfinite(c.grid.cell) && c.grid.cell > 0)) return bad("grid cell is not a positive number");
    if (!(std::isfinite(c.max_sphere_radius) && c.max_sphere_radius >= 0)) return bad("invalid sphere radius");
    if (version != 1 && !(std::isfinite(c.max_join) && c.max_join >= 0)) return bad("invalid block join distance");
    const std::uint64_t levels = std::uint64_t(c.grid.min_levels) * c.grid.extent_levels;
    if (c.grid.min_levels == 0 || c.grid.extent_levels == 0 || levels > 0xffffffffull ||
        levels * levels * levels > std::uint64_t(c.grid.unbounded_code()))
        return bad("grid levels do not fit the code width");
    const std::uint64_t code_bytes = (c.groups * bits + 7) / 8;
    const unsigned count_bytes = index_count_bytes(h);
    if (p.size() != header_bytes + count_bytes * c.fibers + code_bytes)
        return bad("payload size does not match its counts");

    const std::uint8_t* last = b + header_bytes;
    c.last_block_points.resize(c.fibers);
    for (std::uint64_t f = 0; f < c.fibers; ++f) {
        const std::uint16_t n = count_bytes == 1 ? last[f] : std::uint16_t(last[2 * f] | last[2 * f + 1] << 8);
        if (n > h.points_per_block) return bad("a fiber's last block holds more points than a block can");
        c.last_block_points[f] = n;
    }

    c.codes.resize(c.groups);
    const std::uint8_t* s = last + count_bytes * c.fibers;
    const std::uint64_t max_code = levels * levels * levels;
    const std::uint32_t mask = c.grid.unbounded_code();
    for (std::uint64_t k = 0; k < c.groups; ++k) {
        const std::uint64_t bit = k * bits, byte = bit / 8;
        std::uint64_t word = 0;
        std::memcpy(&word, s + byte, std::min<std::uint64_t>(8, code_bytes - byte));
        const auto code = std::uint32_t((word >> (bit % 8)) & mask);
        if (code != mask && code >= max_code) return bad("box code out of range");
        c.codes[k] = code;
    }
    return c;
}

}  // namespace fiblet::detail
