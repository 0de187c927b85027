// BlockIndex: block or group boxes (from the BIDX chunk or computed by
// decoding) and an 8-wide bounding volume hierarchy over them, built in memory.
#include "fiblet/block_index.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>

#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "select/block_decoder.hpp"
#include "core/bytes.hpp"
#include "index/box_tests.hpp"
#include "index/leaf_tests_avx2.hpp"
#include "index/index_chunk.hpp"

namespace fiblet {

namespace {

constexpr std::size_t kFanout = detail::kBoxLanes;  // a node's children are tested together

using detail::BoxLanes;
static_assert(kIndexLeafBlocks <= kFanout, "a leaf's blocks are tested together");
using detail::Overlap;

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
// Blocks first + i for the bits i of `mask`.
void set_bits(std::vector<std::uint64_t>& bits, std::uint32_t first, unsigned mask) {
    for (; mask; mask &= mask - 1) set_bit(bits, first + std::uint32_t(std::countr_zero(mask)));
}

}  // namespace

// first_point_cells(): made on the first frustum query, not on load, which
// region queries would pay for nothing (~5 ms for the medium tractogram's
// 788k blocks, a seventh of its load).
struct BlockIndex::FirstPointCells {
    std::vector<std::uint64_t> before_group;  // per group: its first block's predecessor's cells (or unbounded)
    std::once_flag made;
    std::vector<std::uint64_t> cells;  // as block_cells_
};

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
    std::vector<std::uint8_t> continues;  // per group: its fiber began in an earlier one
    if (per_block) continues.reserve(index.group_first_.capacity());
    for (std::uint64_t f = 0; f < h.fibers; ++f) {
        const std::uint32_t nb = file.block_count(f);
        const std::uint16_t last = c.last_block_points[f];
        if ((nb == 0) != (last == 0)) bad("fiber " + std::to_string(f) + " point count disagrees with its blocks");
        index.fiber_points_[f] = nb == 0 ? 0 : std::uint64_t(nb - 1) * h.points_per_block + last;
        total += index.fiber_points_[f];
        if (!per_block && index.group_first_.size() + detail::index_groups_of_fiber(nb, group_blocks) > c.groups)
            bad("its fibers have more groups of " + std::to_string(group_blocks) + " blocks than it stores");
        for (std::uint32_t k = 0; k < nb; k += group_blocks) {
            index.group_first_.push_back(std::uint32_t(file.first_block(f) + k));
            if (per_block) continues.push_back(k > 0);
        }
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
        index.first_points_ = std::make_shared<FirstPointCells>();
        // Each group's predecessor block, for first_point_cells(): a look-up
        // in file order now, a cache miss a leaf in Morton order later.
        std::vector<std::uint64_t>& before = index.first_points_->before_group;
        before.assign(leaves.size(), detail::kUnboundedCells);  // a fiber's first group: none
        for (std::size_t g = 0; g < leaves.size(); ++g)
            if (continues[g]) before[g] = cells[index.group_first_[g] - 1];
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

std::size_t BlockIndex::group_of(std::uint64_t block) const {
    return std::size_t(std::upper_bound(group_first_.begin(), group_first_.end() - 1, std::uint32_t(block)) -
                       group_first_.begin()) - 1;
}

std::size_t BlockIndex::cell_of(std::uint64_t block) const {
    const std::size_t g = group_of(block);
    return leaf_first_cell_[rank_[g]] + (block - group_first_[g]);
}

Aabb BlockIndex::block_box(std::uint64_t block) const {
    if (!block_cells_.empty()) return detail::cells_bounds(block_cells_[cell_of(block)], cells_origin_, cell_mm_);
    const std::uint32_t pos = rank_[group_of(block)];
    return detail::box_at(boxes_[0][pos / kFanout], pos % kFanout);
}

Aabb BlockIndex::first_point_box(std::uint64_t block) const {
    if (block_cells_.empty()) return block_box(block);
    return detail::cells_bounds<detail::kQuarterCells>(first_point_cells()[cell_of(block)], cells_origin_, cell_mm_);
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

namespace {

// first_point_box's cells: the block's own box in quarter cells, narrowed
// to the previous block's grown by `reach` quarter cells (reach < 0: no
// previous block). Branch-free but for the rare unbounded boxes: it runs
// for every block.
inline std::uint64_t first_point_cells_of(std::uint64_t own, std::uint64_t previous, std::int32_t reach) {
    if (own == detail::kUnboundedCells) return own;
    const bool narrow = reach >= 0 && previous != detail::kUnboundedCells;
    if (!narrow) previous = own, reach = 0;
    constexpr std::uint32_t q = detail::kQuarterCells.subdivision;
    std::uint32_t own_lo[3], own_hi[3], lo[3], hi[3];
    bool disjoint = false;
    for (int a = 0; a < 3; ++a) {
        own_lo[a] = q * detail::cells_lo(own, a), own_hi[a] = q * detail::cells_hi(own, a);
        const auto l = std::max(std::int32_t(own_lo[a]), std::int32_t(q * detail::cells_lo(previous, a)) - reach);
        const auto h = std::min(std::int32_t(own_hi[a]), std::int32_t(q * detail::cells_hi(previous, a)) + reach);
        disjoint |= h < l;
        lo[a] = std::uint32_t(l), hi[a] = std::uint32_t(h);
    }
    // Disjoint only where the index contradicts the blocks: their own box
    // then, as conservative as the rest.
    return disjoint ? detail::pack_cells<detail::kQuarterCells>(own_lo, own_hi)
                    : detail::pack_cells<detail::kQuarterCells>(lo, hi);
}

}  // namespace

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

const std::vector<std::uint64_t>& BlockIndex::first_point_cells() const {
    std::call_once(first_points_->made, [&] {
        // A block's first point lies within max_join of the previous
        // block's last point, so in that block's box grown by max_join, and
        // in its own box: their intersection, in quarter cells, the join
        // plus 0.002 cell rounded up to whole quarters (the sides' float
        // rounding is below the 0.001-cell slack of quantized boxes:
        // index_grid.hpp).
        constexpr double q = detail::kQuarterCells.subdivision;
        const double reach_quarters = std::ceil(q * double(max_join_) / double(cell_mm_) + q * 0.002);
        const bool known = max_join_ >= 0 && cell_mm_ > 0 && reach_quarters < q * detail::kMaxGridLevels;
        const std::int32_t reach = known ? std::int32_t(reach_quarters) : -1;
        std::vector<std::uint64_t>& out = first_points_->cells;
        out.resize(block_cells_.size());
        const std::vector<std::uint64_t>& before = first_points_->before_group;
        constexpr std::size_t kAhead = 16;  // leaves: Morton order jumps around the groups
        for (std::size_t pos = 0; pos < order_.size(); ++pos) {
            if (pos + kAhead < order_.size()) __builtin_prefetch(&before[order_[pos + kAhead]]);
            const std::uint32_t first = leaf_first_cell_[pos], end = leaf_first_cell_[pos + 1];
            out[first] = first_point_cells_of(block_cells_[first], before[order_[pos]], reach);
            for (std::uint32_t i = first + 1; i < end; ++i) out[i] = first_point_cells_of(block_cells_[i], block_cells_[i - 1], reach);
        }
    });
    return first_points_->cells;
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
    if (order_.empty() || is_unbounded(root_)) return std::nullopt;
    return root_;
}

template <class BoxOf>
void BlockIndex::build(std::vector<std::uint64_t>& keyed, const BoxOf& box_of) {
    const std::size_t n = keyed.size();
    radix_sort(keyed, 31);
    // Filled by push_back: no zeroing pass over memory written right after.
    order_.clear(), order_.reserve(n);
    leaf_blocks_.clear(), leaf_blocks_.reserve(n);
    rank_.resize(n);
    std::vector<Aabb> boxes;  // of one level, in Morton order
    boxes.reserve(n);
    for (std::size_t pos = 0; pos < n; ++pos) {
        const auto group = std::uint32_t(keyed[pos]);
        order_.push_back(group);
        leaf_blocks_.push_back({group_first_[group], group_first_[group + 1]});
        rank_[group] = std::uint32_t(pos);
        boxes.push_back(box_of(group));
    }
    // Levels of the tree, up to the root: each node bounds kFanout
    // consecutive children, stored side by side (a last group's missing
    // boxes repeat its first).
    boxes_.clear();
    do {
        std::vector<detail::BoxGroup> groups((boxes.size() + kFanout - 1) / kFanout);
        std::vector<Aabb> parents(groups.size(), empty_box());
        for (std::size_t i = 0; i < groups.size() * kFanout; ++i) {
            const Aabb& b = boxes[i < boxes.size() ? i : i / kFanout * kFanout];
            detail::set_box(groups[i / kFanout], i % kFanout, b);
            grow(parents[i / kFanout], b);
        }
        boxes_.push_back(std::move(groups));
        boxes.swap(parents);
    } while (boxes.size() > 1);
    root_ = boxes.empty() ? empty_box() : boxes[0];
}

template <BlockIndex::LeafBoxes kLeafBoxes, class Test>
void BlockIndex::collect(const Test& test, std::vector<std::uint64_t>& bits, std::vector<std::uint64_t>* inside) const {
    constexpr bool first_points = kLeafBoxes == LeafBoxes::first_point;
    const std::vector<std::uint64_t>& leaf_cells = !first_points || block_cells_.empty() ? block_cells_ : first_point_cells();
    constexpr detail::CellLayout kLeafLayout = first_points ? detail::kQuarterCells : detail::kGridCells;
    const std::size_t n = order_.size();
    bits.resize((blocks_ + 63) / 64, 0);
    if (inside) inside->resize((blocks_ + 63) / 64, 0);
    if (n == 0) return;
    // The blocks of the leaf at Morton position `pos`.
    auto mark = [&](std::vector<std::uint64_t>& to, std::size_t pos) {
        for (std::uint32_t b = leaf_blocks_[pos].first; b < leaf_blocks_[pos].end; ++b) set_bit(to, b);
    };
    auto mark_all = [&](std::size_t first, std::size_t last) {
        for (std::size_t pos = first; pos < std::min(last, n); ++pos) {
            mark(bits, pos);
            if (inside) mark(*inside, pos);
        }
    };
    // A leaf the region meets: its blocks, or (when it meets it partly and
    // the blocks have boxes of their own) those whose own box meets it.
    auto leaf = [&](std::size_t pos, Overlap o, detail::Narrowing active) {
        if (o == Overlap::partial && !leaf_cells.empty()) {
            const BlockRange r = leaf_blocks_[pos];
#ifdef FIBLET_POINTS_AVX2
            if constexpr (detail::HasLeafVerdicts8<Test>) {
                if (detail::use_avx2_loops()) {
                    const detail::LeafVerdicts v = detail::leaf_verdicts_avx2<kLeafLayout>(
                        test, &leaf_cells[leaf_first_cell_[pos]], r.end - r.first, cells_origin_, cell_mm_, active);
                    set_bits(bits, r.first, v.near);
                    if (inside) set_bits(*inside, r.first, v.inside);
                    return;
                }
            }
#endif
            Overlap ob[kFanout];
            detail::Narrowing unused[kFanout];
            detail::classify(test,
                             BoxLanes::of_cells<kLeafLayout>(&leaf_cells[leaf_first_cell_[pos]], r.end - r.first, cells_origin_, cell_mm_),
                             r.end - r.first, active, ob, unused);
            for (std::uint32_t b = r.first; b < r.end; ++b) {
                if (ob[b - r.first] != Overlap::outside) set_bit(bits, b);
                if (ob[b - r.first] == Overlap::inside && inside) set_bit(*inside, b);
            }
            return;
        }
        mark(bits, pos);
        if (o == Overlap::inside && inside) mark(*inside, pos);
    };
    // Node j of level k, which the region meets partly (`active`: what it
    // hands its children): its children tested together. It covers Morton
    // positions [j * span[k], (j + 1) * span[k]), span[k] = 8^(k+1).
    std::vector<std::size_t> span(boxes_.size());
    for (std::size_t k = 0, s = kFanout; k < boxes_.size(); ++k, s *= kFanout) span[k] = s;
    auto visit = [&](auto& self, std::size_t k, std::size_t j, detail::Narrowing active) -> void {
        const std::size_t first = j * kFanout, count = std::min(kFanout, (k == 0 ? n : boxes_[k - 1].size()) - first);
        Overlap o[kFanout];
        detail::Narrowing narrowed[kFanout];
        detail::classify(test, BoxLanes::of(boxes_[k][j]), count, active, o, narrowed);
        for (std::size_t i = 0; i < count; ++i) {
            const std::size_t c = first + i;
            if (o[i] == Overlap::outside) continue;
            if (k == 0) leaf(c, o[i], narrowed[i]);
            else if (o[i] == Overlap::inside) mark_all(c * span[k - 1], (c + 1) * span[k - 1]);
            else self(self, k - 1, c, narrowed[i]);
        }
    };
    Overlap root = Overlap::partial;
    detail::Narrowing narrowed = detail::kEveryPlane;
    detail::classify(test, BoxLanes::of(root_), 1, detail::kEveryPlane, &root, &narrowed);
    if (root == Overlap::inside) mark_all(0, n);
    else if (root == Overlap::partial) visit(visit, boxes_.size() - 1, 0, narrowed);
}

void BlockIndex::blocks_near_sphere(Vec3f c, float radius, std::vector<std::uint64_t>& bits,
                                    std::vector<std::uint64_t>* inside) const {
    collect<LeafBoxes::own>(detail::SphereTest(c, radius), bits, inside);
}

void BlockIndex::blocks_near_box(const Aabb& r, std::vector<std::uint64_t>& bits,
                                 std::vector<std::uint64_t>* inside) const {
    collect<LeafBoxes::own>(detail::BoxTest{r}, bits, inside);
}

void BlockIndex::blocks_near_mask(const ImageMask& mask, std::vector<std::uint64_t>& bits,
                                  std::vector<std::uint64_t>* inside) const {
    collect<LeafBoxes::own>(detail::MaskTest{mask}, bits, inside);
}

void BlockIndex::blocks_near_frustum(const Frustum& f, float margin, std::vector<std::uint64_t>& bits) const {
    collect<LeafBoxes::own>(detail::FrustumTest{f, margin}, bits, nullptr);
}

void BlockIndex::blocks_starting_near_frustum(const Frustum& f, float margin, std::vector<std::uint64_t>& bits) const {
    // The nodes bound the blocks' boxes, which hold the first points' boxes.
    collect<LeafBoxes::first_point>(detail::FrustumTest{f, margin}, bits, nullptr);
}

}  // namespace fiblet
