#include "index/index_chunk.hpp"

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

// Version-3 cells per block path: the grid cell is half the longest path a
// block may take (about 3 mm for 60 points at 0.1 mm), where the coded
// boxes cost about 5 bits a block (formats/fft-index.md §3).
constexpr double kCellsPerBlockPath = 2;

// Largest v with v^3 < 2^bits - 1 (so that the all-ones code stays free).
std::uint32_t max_axis_levels(unsigned bits) {
    const std::uint64_t limit = (std::uint64_t{1} << bits) - 1;
    std::uint64_t v = std::uint64_t(std::cbrt(double(limit))) + 2;
    while (v * v * v >= limit) --v;
    return std::uint32_t(v);
}

}  // namespace

IndexGrid IndexGrid::for_blocks(const FftHeader& h) {
    IndexGrid g;
    const float lo = float(-kCubeMargin);
    g.origin = h.to_world(lo, lo, lo);
    const double range = double(h.scaling) * (1 + 2 * kCubeMargin);
    // A block spans at most points_per_block steps (with the rounding of its
    // second anchor), and never more than the range; the grid has at most
    // kMaxGridLevels cells a side (a cell of half the range at most: a float
    // even for a range near the float limit).
    const double path = std::min(double(h.points_per_block) * double(h.step) * double(h.scaling), range);
    const double cell = std::max(path / kCellsPerBlockPath, range / double(kMaxGridLevels - 1));
    g.cell = std::nextafter(float(cell), std::numeric_limits<float>::infinity());
    g.min_levels = std::uint32_t(std::min<double>(kMaxGridLevels, std::ceil(range / double(g.cell)) + 1));
    g.extent_levels = kMaxBoxExtent + 1;
    return g;
}

IndexGrid IndexGrid::for_groups(const FftHeader& h, unsigned bits, std::uint32_t group_blocks) {
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

// Cells i..j (first, last) of one axis (origin o) holding [lo, hi] with
// the slack, or nullopt when they do not fit the grid. They must also hold
// it as readers decode them, in float (bounds()): the double arithmetic
// that picks them does not see float rounding flatten a cell (an origin
// near the float range: 1.7e38 mm plus a few mm is 1.7e38 mm).
std::optional<std::pair<std::uint32_t, std::uint32_t>> IndexGrid::axis_cells(float o, float lo, float hi) const {
    const double b = (double(lo) - o) / cell - kSlackCells;
    const double t = (double(hi) - o) / cell + kSlackCells;
    if (!(b >= 0 && t >= b && t < double(min_levels + extent_levels))) return std::nullopt;
    const auto i = std::uint32_t(std::floor(b));
    const auto j = std::uint32_t(std::ceil(t));
    if (i >= min_levels || j - i >= extent_levels) return std::nullopt;
    if (!(o + float(i) * cell <= lo && o + float(j) * cell >= hi)) return std::nullopt;
    return std::pair{i, j};
}

std::uint32_t IndexGrid::encode(const Aabb& box) const {
    std::uint32_t code = 0, scale = 1;
    const float lo[3] = {box.min.x, box.min.y, box.min.z}, hi[3] = {box.max.x, box.max.y, box.max.z};
    const float o[3] = {origin.x, origin.y, origin.z};
    for (int a = 0; a < 3; ++a) {
        const auto cells = axis_cells(o[a], lo[a], hi[a]);
        if (!cells) return unbounded_code();
        const auto [i, j] = *cells;
        code += (i * extent_levels + (j - i)) * scale;
        scale *= axis_levels();
    }
    return code;
}

std::optional<GridBox> IndexGrid::quantize(const Aabb& box) const {
    GridBox q;
    const float lo[3] = {box.min.x, box.min.y, box.min.z}, hi[3] = {box.max.x, box.max.y, box.max.z};
    const float o[3] = {origin.x, origin.y, origin.z};
    for (int a = 0; a < 3; ++a) {
        const auto cells = axis_cells(o[a], lo[a], hi[a]);
        if (!cells) return std::nullopt;
        const auto [i, j] = *cells;
        q.lo[a] = i, q.extent[a] = std::uint8_t(j - i);
    }
    return q;
}

Aabb IndexGrid::bounds(const GridBox& b) const {
    // As IndexBoxDecoder computes version-2 boxes: origin + float(i) * cell.
    auto side = [&](float o, std::uint32_t i) { return o + float(i) * cell; };
    return {{side(origin.x, b.lo[0]), side(origin.y, b.lo[1]), side(origin.z, b.lo[2])},
            {side(origin.x, b.lo[0] + b.extent[0]), side(origin.y, b.lo[1] + b.extent[1]),
             side(origin.z, b.lo[2] + b.extent[2])}};
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
IndexChunk parse_v3(const std::vector<std::uint8_t>& p, const FftHeader& h, const std::string& file) {
    if (p.size() < kIndexChunkHeaderBytes) malformed(file, "truncated header");
    const std::uint8_t* b = p.data();
    IndexChunk c;
    c.version = 3;
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

std::vector<Aabb> index_block_boxes(const IndexChunk& c, const std::vector<std::uint8_t>& payload,
                                    const FftFile& file) {
    std::vector<bool> first_of_fiber(c.blocks, false);  // a bit a block, not 4 bytes a fiber
    for (std::uint64_t f = 0; f < c.fibers; ++f)
        if (file.block_count(f) > 0) first_of_fiber[file.first_block(f)] = true;
    const DecodedBoxes d = decode_box_stream(payload.data() + c.box_stream_offset, c.box_stream_bytes,
                                             first_of_fiber, c.grid.min_levels);
    if (!d.error.empty()) malformed(file.path(), d.error);
    std::vector<Aabb> boxes;
    boxes.reserve(d.boxes.size());
    for (const auto& box : d.boxes) boxes.push_back(box ? c.grid.bounds(*box) : unbounded_box());
    return boxes;
}

IndexChunk parse_index_chunk(const std::vector<std::uint8_t>& p, const FftHeader& h, const std::string& file) {
    if (p.size() < 4) malformed(file, "truncated header");
    const std::uint32_t version = get_le<std::uint32_t>(p.data());
    if (version == kIndexChunkVersion) return parse_v3(p, h, file);
    if (version == 1 || version == 2) return parse_v1_v2(p, h, file, version);
    malformed(file, "unsupported version " + std::to_string(version));
}

}  // namespace fiblet::detail
