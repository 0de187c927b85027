// The block index's grid: which grid a file's index uses, and boxes
// quantized onto it (formats/fft-index.md §3, §5).
#include "index/index_grid.hpp"

#include <algorithm>
#include <cmath>

namespace fiblet::detail {

namespace {

// Slack, in cells, between a box and its quantized bounds: far above the
// float rounding of origin + i * cell, far below a cell.
constexpr double kSlackCells = 1e-3;
// Margin of the grid around the normalized cube, in normalized units:
// decoded points may stray a few micrometres outside it (about 1e-4).
constexpr double kCubeMargin = 1.0 / 1024;

// Cells per block path of versions 3 and 4: the grid cell is half the longest path a
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
        q.lo[a] = std::uint16_t(i), q.extent[a] = std::uint8_t(j - i);
    }
    return q;
}

}  // namespace fiblet::detail
