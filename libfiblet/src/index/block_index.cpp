// BlockIndex: block or group boxes (from the BIDX chunk or computed by
// decoding) and an 8-wide bounding volume hierarchy over them, built in memory.
#include "fiblet/block_index.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "select/block_decoder.hpp"
#include "core/bytes.hpp"
#include "index/index_chunk.hpp"

namespace fiblet {

namespace {

constexpr std::size_t kFanout = 8;

enum class Overlap { outside, partial, inside };

Aabb empty_box() {
    const float inf = std::numeric_limits<float>::infinity();
    return {{inf, inf, inf}, {-inf, -inf, -inf}};
}

void grow(Aabb& a, const Aabb& b) {
    a.min = {std::min(a.min.x, b.min.x), std::min(a.min.y, b.min.y), std::min(a.min.z, b.min.z)};
    a.max = {std::max(a.max.x, b.max.x), std::max(a.max.y, b.max.y), std::max(a.max.z, b.max.z)};
}

bool is_unbounded(const Aabb& b) { return b.max.x >= detail::kUnboundedExtentMm; }

// 10 bits of x, y, z interleaved.
std::uint32_t spread_bits(std::uint32_t v) {
    v = (v | (v << 16)) & 0x030000ffu;
    v = (v | (v << 8)) & 0x0300f00fu;
    v = (v | (v << 4)) & 0x030c30c3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}

// Sorts (key << 32 | value) pairs by key: LSD radix sort, 11 bits a pass.
void radix_sort(std::vector<std::uint64_t>& items, unsigned key_bits) {
    std::vector<std::uint64_t> tmp(items.size());
    for (unsigned shift = 32; shift < 32 + key_bits; shift += 11) {
        std::vector<std::size_t> count(2049, 0);
        for (std::uint64_t v : items) ++count[((v >> shift) & 2047) + 1];
        for (std::size_t i = 1; i < count.size(); ++i) count[i] += count[i - 1];
        for (std::uint64_t v : items) tmp[count[(v >> shift) & 2047]++] = v;
        items.swap(tmp);
    }
}

void set_bit(std::vector<std::uint64_t>& bits, std::uint32_t b) { bits[b >> 6] |= std::uint64_t{1} << (b & 63); }

}  // namespace

std::optional<std::uint32_t> BlockIndex::stored_version(const FftFile& file) {
    const TrailerChunk* chunk = file.find_chunk(kBlockIndexTag);
    if (!chunk) return std::nullopt;
    if (chunk->payload.size() < 4)
        throw Error(Errc::fft_format, file.path() + ": malformed BIDX (block index) chunk: shorter than its version field");
    return detail::get_le<std::uint32_t>(chunk->payload.data());
}

BlockIndex BlockIndex::load(const FftFile& file) {
    const TrailerChunk* chunk = file.find_chunk(kBlockIndexTag);
    if (!chunk) return compute(file);
    const FftHeader& h = file.header();
    const detail::IndexChunk c = detail::parse_index_chunk(chunk->payload, h, file.path());
    auto bad = [&](const std::string& what) {
        throw Error(Errc::fft_format, file.path() + ": malformed BIDX (block index) chunk: " + what);
    };
    BlockIndex index;
    index.source_ = Source::chunk;
    index.chunk_version_ = c.version;
    index.blocks_ = h.blocks;
    index.max_sphere_radius_ = c.max_sphere_radius;
    index.max_join_ = c.max_join;
    // Fiber point counts: full blocks but the last (checked against the
    // header's total); groups: G blocks at a time from each fiber's first
    // (versions 3 and 4: the hierarchy's leaves, over the blocks' own boxes).
    const bool per_block = c.version >= detail::kIndexChunkV3Version;
    const std::uint32_t group_blocks = per_block ? kIndexLeafBlocks : c.group_blocks;
    index.fiber_points_.resize(h.fibers);
    index.group_first_.clear();
    index.group_first_.reserve((per_block ? h.blocks / group_blocks + h.fibers : c.groups) + 1);
    std::uint64_t total = 0;
    for (std::uint64_t f = 0; f < h.fibers; ++f) {
        const std::uint32_t nb = file.block_count(f);
        const std::uint16_t last = c.last_block_points[f];
        if ((nb == 0) != (last == 0)) bad("fiber " + std::to_string(f) + " point count disagrees with its blocks");
        index.fiber_points_[f] = nb == 0 ? 0 : std::uint64_t(nb - 1) * h.points_per_block + last;
        total += index.fiber_points_[f];
        if (!per_block && index.group_first_.size() + detail::index_groups_of_fiber(nb, group_blocks) > c.groups)
            bad("its fibers have more groups of " + std::to_string(group_blocks) + " blocks than it stores");
        for (std::uint32_t k = 0; k < nb; k += group_blocks)
            index.group_first_.push_back(std::uint32_t(file.first_block(f) + k));
    }
    if (!per_block && index.group_first_.size() != c.groups)
        bad("it stores " + std::to_string(c.groups) + " groups, its fibers have " +
            std::to_string(index.group_first_.size()));
    index.group_first_.push_back(std::uint32_t(h.blocks));
    if (total != h.points)
        bad("its fibers hold " + std::to_string(total) + " points, the header says " + std::to_string(h.points));
    if (per_block) {
        const std::vector<std::uint64_t> cells = detail::index_block_cells(c, chunk->payload, file);
        index.cells_origin_ = c.grid.origin, index.cell_mm_ = c.grid.cell;
        std::vector<Aabb> leaves(index.group_first_.size() - 1);
        for (std::size_t g = 0; g < leaves.size(); ++g) {
            const std::uint32_t first = index.group_first_[g], end = index.group_first_[g + 1];
            leaves[g] = index.cells_union(&cells[first], end - first);
        }
        index.set_groups(leaves);
        index.sort_block_cells(cells);
        return index;
    }
    // Morton keys straight from the codes' cells, then boxes decoded in that order.
    const detail::IndexBoxDecoder decoder(c.grid);
    unsigned shift = 0;
    while ((decoder.max_centre2() >> shift) >= 1024) ++shift;
    std::vector<std::uint64_t> keyed(c.groups);
    for (std::uint64_t g = 0; g < c.groups; ++g) {
        std::uint64_t key = std::uint64_t{1} << 30;
        if (!decoder.unbounded(c.codes[g])) {
            std::uint32_t m[3];
            decoder.centre2(c.codes[g], m);
            key = spread_bits(m[0] >> shift) | spread_bits(m[1] >> shift) << 1 | spread_bits(m[2] >> shift) << 2;
        }
        keyed[g] = key << 32 | g;
    }
    index.build(keyed, [&](std::uint32_t g) { return decoder.box(c.codes[g]); });
    return index;
}

Aabb BlockIndex::block_box(std::uint64_t block) const {
    const auto g = std::size_t(std::upper_bound(group_first_.begin(), group_first_.end() - 1, std::uint32_t(block)) -
                               group_first_.begin()) - 1;
    if (!block_cells_.empty())
        return detail::cells_bounds(block_cells_[leaf_first_cell_[rank_[g]] + (block - group_first_[g])], cells_origin_,
                                    cell_mm_);
    return sorted_boxes_[rank_[g]];
}

Aabb BlockIndex::cells_union(const std::uint64_t* cells, std::size_t n) const {
    std::uint32_t lo[3] = {~0u, ~0u, ~0u}, hi[3] = {0, 0, 0};
    for (std::size_t i = 0; i < n; ++i) {
        if (cells[i] == detail::kUnboundedCells) return detail::unbounded_box();
        for (int a = 0; a < 3; ++a)
            lo[a] = std::min(lo[a], detail::cells_lo(cells[i], a)), hi[a] = std::max(hi[a], detail::cells_hi(cells[i], a));
    }
    // Sides grow with their cell numbers: the union of the boxes in mm.
    return detail::cells_bounds(lo, hi, cells_origin_, cell_mm_);
}

void BlockIndex::sort_block_cells(const std::vector<std::uint64_t>& cells) {
    // Leaf after leaf in Morton order, as a query walks them (its partial
    // leaves' blocks then lie side by side, not one cache miss each).
    block_cells_.reserve(cells.size());
    leaf_first_cell_.reserve(order_.size() + 1);
    constexpr std::size_t kAhead = 16;  // leaves: Morton order jumps around the file
    for (std::size_t pos = 0; pos < order_.size(); ++pos) {
        if (pos + kAhead < order_.size()) __builtin_prefetch(&cells[group_first_[order_[pos + kAhead]]]);
        const std::uint32_t g = order_[pos];
        leaf_first_cell_.push_back(std::uint32_t(block_cells_.size()));
        block_cells_.insert(block_cells_.end(), cells.begin() + group_first_[g], cells.begin() + group_first_[g + 1]);
    }
    leaf_first_cell_.push_back(std::uint32_t(block_cells_.size()));
}

BlockIndex BlockIndex::compute(const FftFile& file) {
    const FftHeader& h = file.header();
    const DecodeContext ctx(h);
    const std::uint32_t bb = h.block_bytes();
    BlockIndex index;
    index.source_ = Source::decoded;
    std::vector<Aabb> boxes(h.blocks);
    std::vector<std::uint16_t> counts(h.blocks);
    std::vector<std::uint8_t> raw;
    std::vector<float> xyz;
    const std::uint64_t chunk = std::max<std::uint64_t>(1, (1u << 21) / h.points_per_block);  // blocks of ~2M points
    for (std::uint64_t b0 = 0; b0 < h.blocks; b0 += chunk) {
        const std::uint64_t n = std::min<std::uint64_t>(chunk, h.blocks - b0);
        raw.resize(n * bb);
        file.read_blocks(b0, n, raw.data());
        xyz.resize(3 * count_block_points(ctx, raw.data(), n));
        detail::decode_selected_blocks(ctx, raw.data(), n, xyz.data());
        const float* p = xyz.data();
        for (std::uint64_t k = 0; k < n; ++k) {
            const std::uint8_t* block = &raw[k * bb];
            const std::uint32_t np = block_flags(h, block).point_count;
            Aabb box{{p[0], p[1], p[2]}, {p[0], p[1], p[2]}};
            for (std::uint32_t i = 1; i < np; ++i)
                grow(box, {{p[3 * i], p[3 * i + 1], p[3 * i + 2]}, {p[3 * i], p[3 * i + 1], p[3 * i + 2]}});
            boxes[b0 + k] = box;
            counts[b0 + k] = std::uint16_t(np);
            index.max_sphere_radius_ = std::max(index.max_sphere_radius_, block_bounding_sphere(h, block).radius);
            p += 3 * np;
        }
    }
    index.fiber_points_.resize(h.fibers);
    for (std::uint64_t f = 0; f < h.fibers; ++f) {
        std::uint64_t points = 0;
        for (std::uint64_t b = file.first_block(f), e = b + file.block_count(f); b < e; ++b) points += counts[b];
        index.fiber_points_[f] = points;
    }
    index.blocks_ = h.blocks;
    index.set_blocks(std::move(boxes));
    return index;
}

void BlockIndex::set_blocks(std::vector<Aabb> boxes) {
    group_first_.resize(boxes.size() + 1);
    for (std::size_t b = 0; b < group_first_.size(); ++b) group_first_[b] = std::uint32_t(b);
    set_groups(boxes);
}

void BlockIndex::set_groups(const std::vector<Aabb>& boxes) {
    const std::size_t n = boxes.size();
    // Morton order of the box centres over the bounds of the bounded ones;
    // unbounded boxes go last, so that they spoil one path of the tree only.
    Aabb all = empty_box();
    for (const Aabb& b : boxes)
        if (!is_unbounded(b)) grow(all, b);
    auto axis_cell = [](float v, float lo, float hi) {
        const float t = hi > lo ? (v - lo) / (hi - lo) : 0.0f;
        return std::uint32_t(std::clamp(t * 1023.0f, 0.0f, 1023.0f));
    };
    std::vector<std::uint64_t> keyed(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Aabb& b = boxes[i];
        std::uint64_t key = std::uint64_t{1} << 30;
        if (!is_unbounded(b)) {
            const float cx = 0.5f * (b.min.x + b.max.x), cy = 0.5f * (b.min.y + b.max.y),
                        cz = 0.5f * (b.min.z + b.max.z);
            key = spread_bits(axis_cell(cx, all.min.x, all.max.x)) |
                  spread_bits(axis_cell(cy, all.min.y, all.max.y)) << 1 |
                  spread_bits(axis_cell(cz, all.min.z, all.max.z)) << 2;
        }
        keyed[i] = key << 32 | i;
    }
    build(keyed, [&](std::uint32_t b) { return boxes[b]; });
}

std::optional<Aabb> BlockIndex::bounds() const {
    // The hierarchy's root bounds every box (an unbounded one spoils it).
    if (sorted_boxes_.empty() || is_unbounded(levels_.back().front())) return std::nullopt;
    return levels_.back().front();
}

template <class BoxOf>
void BlockIndex::build(std::vector<std::uint64_t>& keyed, const BoxOf& box_of) {
    const std::size_t n = keyed.size();
    radix_sort(keyed, 31);
    // Filled by push_back: no zeroing pass over memory written right after.
    order_.clear(), order_.reserve(n);
    sorted_boxes_.clear(), sorted_boxes_.reserve(n);
    rank_.resize(n);
    for (std::size_t pos = 0; pos < n; ++pos) {
        const auto group = std::uint32_t(keyed[pos]);
        order_.push_back(group);
        rank_[group] = std::uint32_t(pos);
        sorted_boxes_.push_back(box_of(group));
    }
    // Levels of the tree: each node bounds kFanout consecutive children.
    levels_.clear();
    const std::vector<Aabb>* below = &sorted_boxes_;
    while (below->size() > 1 || levels_.empty()) {
        std::vector<Aabb> level((below->size() + kFanout - 1) / kFanout, empty_box());
        for (std::size_t i = 0; i < below->size(); ++i) grow(level[i / kFanout], (*below)[i]);
        levels_.push_back(std::move(level));
        below = &levels_.back();
        if (below->empty()) break;
    }
}

template <class Classify>
void BlockIndex::collect(const Classify& classify, std::vector<std::uint64_t>& bits,
                         std::vector<std::uint64_t>* inside) const {
    const std::size_t n = sorted_boxes_.size();
    bits.resize((blocks_ + 63) / 64, 0);
    if (inside) inside->resize((blocks_ + 63) / 64, 0);
    if (n == 0) return;
    // The blocks of the group at Morton position `pos`.
    auto mark = [&](std::vector<std::uint64_t>& to, std::size_t pos) {
        const std::uint32_t g = order_[pos];
        for (std::uint32_t b = group_first_[g]; b < group_first_[g + 1]; ++b) set_bit(to, b);
    };
    // Those of its blocks whose own box meets the region.
    auto mark_blocks = [&](std::size_t pos) {
        const std::uint32_t g = order_[pos];
        const std::uint64_t* cells = &block_cells_[leaf_first_cell_[pos]];
        for (std::uint32_t b = group_first_[g]; b < group_first_[g + 1]; ++b, ++cells) {
            const Overlap o = classify(detail::cells_bounds(*cells, cells_origin_, cell_mm_));
            if (o != Overlap::outside) set_bit(bits, b);
            if (o == Overlap::inside && inside) set_bit(*inside, b);
        }
    };
    // Positions covered by node j of level k: [j * span, (j + 1) * span), span = 8^(k+1).
    auto mark_all = [&](std::size_t first, std::size_t last) {
        for (std::size_t pos = first; pos < std::min(last, n); ++pos) {
            mark(bits, pos);
            if (inside) mark(*inside, pos);
        }
    };
    auto visit = [&](auto& self, std::size_t k, std::size_t j, std::size_t span) -> void {
        const Overlap o = classify(levels_[k][j]);
        if (o == Overlap::outside) return;
        if (o == Overlap::inside) return mark_all(j * span, (j + 1) * span);
        if (k == 0) {
            for (std::size_t pos = j * kFanout; pos < std::min(n, (j + 1) * kFanout); ++pos) {
                const Overlap b = classify(sorted_boxes_[pos]);
                if (b == Overlap::partial && !block_cells_.empty()) {
                    mark_blocks(pos);
                    continue;
                }
                if (b != Overlap::outside) mark(bits, pos);
                if (b == Overlap::inside && inside) mark(*inside, pos);
            }
            return;
        }
        const std::size_t children = levels_[k - 1].size();
        for (std::size_t c = j * kFanout; c < std::min(children, (j + 1) * kFanout); ++c)
            self(self, k - 1, c, span / kFanout);
    };
    std::size_t span = kFanout;
    for (std::size_t k = 1; k < levels_.size(); ++k) span *= kFanout;
    const std::size_t top = levels_.size() - 1;
    for (std::size_t j = 0; j < levels_[top].size(); ++j) visit(visit, top, j, span);
}

void BlockIndex::blocks_near_sphere(Vec3f c, float radius, std::vector<std::uint64_t>& bits,
                                    std::vector<std::uint64_t>* inside) const {
    // Squared distances with a relative slack, so float rounding never culls
    // a block whose point passes Region::contains.
    const float r2 = radius * radius * (1 + 1e-5f);
    collect(
        [&](const Aabb& b) {
            auto d = [](float v, float lo, float hi) { return v < lo ? lo - v : (v > hi ? v - hi : 0.0f); };
            const float dx = d(c.x, b.min.x, b.max.x), dy = d(c.y, b.min.y, b.max.y), dz = d(c.z, b.min.z, b.max.z);
            if (dx * dx + dy * dy + dz * dz > r2) return Overlap::outside;
            auto far = [](float v, float lo, float hi) { return std::max(v - lo, hi - v); };
            const float fx = far(c.x, b.min.x, b.max.x), fy = far(c.y, b.min.y, b.max.y),
                        fz = far(c.z, b.min.z, b.max.z);
            return fx * fx + fy * fy + fz * fz <= radius * radius * (1 - 1e-5f) ? Overlap::inside : Overlap::partial;
        },
        bits, inside);
}

void BlockIndex::blocks_near_box(const Aabb& r, std::vector<std::uint64_t>& bits,
                                 std::vector<std::uint64_t>* inside) const {
    collect(
        [&](const Aabb& b) {
            if (b.max.x < r.min.x || b.min.x > r.max.x || b.max.y < r.min.y || b.min.y > r.max.y ||
                b.max.z < r.min.z || b.min.z > r.max.z)
                return Overlap::outside;
            const bool within = b.min.x >= r.min.x && b.max.x <= r.max.x && b.min.y >= r.min.y &&
                                b.max.y <= r.max.y && b.min.z >= r.min.z && b.max.z <= r.max.z;
            return within ? Overlap::inside : Overlap::partial;
        },
        bits, inside);
}

void BlockIndex::blocks_near_mask(const ImageMask& mask, std::vector<std::uint64_t>& bits,
                                  std::vector<std::uint64_t>* inside) const {
    collect(
        [&](const Aabb& b) {
            switch (mask.classify(b)) {
                case ImageMask::Overlap::outside: return Overlap::outside;
                case ImageMask::Overlap::inside: return Overlap::inside;
                case ImageMask::Overlap::partial: break;
            }
            return Overlap::partial;
        },
        bits, inside);
}

void BlockIndex::blocks_near_frustum(const Frustum& f, float margin, std::vector<std::uint64_t>& bits) const {
    collect(
        [&](const Aabb& b) {
            if (!box_intersects_frustum(f, b, margin)) return Overlap::outside;
            // Inside when even the nearest corner is within the margin of every
            // plane, with room for rounding between corners.
            for (const Plane& p : f.planes) {
                const Vec3f c{p.n.x >= 0 ? b.min.x : b.max.x, p.n.y >= 0 ? b.min.y : b.max.y,
                              p.n.z >= 0 ? b.min.z : b.max.z};
                if (p.n.x * c.x + p.n.y * c.y + p.n.z * c.z + p.d < -margin + 1e-3f) return Overlap::partial;
            }
            return Overlap::inside;
        },
        bits, nullptr);
}

}  // namespace fiblet
