// FiberRegionTest::kept_fibers and decode_kept_into: a query's regions
// decided on all threads, one part of whole fibers (up to kPartPoints
// points in full blocks) per task. A part's fibers are decided from the
// index's bitmaps (no block read), then from their blocks: their anchors
// (decoded points, stored exactly), then the blocks whose bounds from the
// headers may meet a region, decoded. decode_kept_into then decodes the
// part's kept fibers while its blocks are in cache, after the points of
// the parts before it: each part publishes where its points end once it
// knows how many it keeps.
#include <algorithm>
#include <string>

#include "container/fiber_spans.hpp"
#include "core/ordered_ends.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fiber_regions.hpp"
#include "fiblet/parallel.hpp"
#include "fiblet/view.hpp"
#include "select/block_bits.hpp"
#include "select/block_bounds.hpp"
#include "select/query_checks.hpp"

namespace fiblet {

using detail::any_bit;
using detail::has_bit;

namespace {

// Points of whole fibers a task decides: 4096 blocks of 60 (~300 kB of
// 76-byte blocks, their points ~3 MB: in cache from read to decode), as
// many points of larger blocks.
constexpr std::uint64_t kPartPoints = std::uint64_t{4096} * 60;

// Parts of whole fibers within the candidate ranges: part p is fibers
// [first[p], end[p]), its flags from flag_at[p] on.
struct Parts {
    std::vector<std::uint64_t> first, end, flag_at{0};
    std::size_t size() const { return first.size(); }
};

Parts parts_of(const FftFile& file, std::span<const FiberRange> candidates) {
    const std::uint64_t part_blocks = std::max<std::uint64_t>(kPartPoints / file.header().points_per_block, 1);
    Parts parts;
    for (const FiberRange& r : candidates) {
        if (r.first > r.last || r.last >= file.header().fibers || (!parts.end.empty() && r.first < parts.end.back()))
            throw Error(Errc::invalid_argument,
                        file.path() + ": fiber ranges must be ascending, disjoint and in the file");
        for (std::uint64_t f = r.first; f <= r.last; f = parts.end.back()) {
            parts.first.push_back(f);
            parts.end.push_back(detail::fibers_end(file, f, r.last + 1, part_blocks));
            parts.flag_at.push_back(parts.flag_at.back() + parts.end.back() - f);
        }
    }
    return parts;
}

}  // namespace

FiberRegionTest::Fate FiberRegionTest::fate_by_index(std::uint64_t fiber) const {
    const std::uint64_t first = file_.first_block(fiber), end = first + file_.block_count(fiber);
    if (first == end) return Fate::dropped;  // no points: never kept
    bool decided = true;
    for (std::size_t i = 0; i < include_.size(); ++i) {
        if (any_bit(inside_include_[i], first, end)) continue;
        if (!any_bit(near_include_[i], first, end)) return Fate::dropped;
        decided = false;
    }
    for (const auto& near : near_exclude_) decided = decided && !any_bit(near, first, end);
    return decided ? Fate::kept : Fate::undecided;
}

bool FiberRegionTest::anchor_in(const Region& r, const std::vector<std::uint64_t>& near, std::uint64_t fiber,
                                const std::uint8_t* blocks) const {
    const FftHeader& h = file_.header();
    const std::uint64_t first = file_.first_block(fiber), count = file_.block_count(fiber);
    for (std::uint64_t b = 0; b < count; ++b) {
        if (!has_bit(near, first + b)) continue;
        const std::uint8_t* block = blocks + b * h.block_bytes();
        // The anchors are decoded as stored (an ENDS fraction moves a
        // block's third point or later: end_fraction_applies).
        const auto a = block_anchors_normalized(h, block);
        if (r.contains(h.to_world(a[0], a[1], a[2]))) return true;
        if (block_flags(h, block).point_count >= 2 && r.contains(h.to_world(a[3], a[4], a[5]))) return true;
    }
    return false;
}

bool FiberRegionTest::point_in(const Region& r, const std::vector<std::uint64_t>& near, std::uint64_t fiber,
                               const std::uint8_t* blocks, const DecodeContext& ctx) const {
    const FftHeader& h = file_.header();
    const std::uint64_t first = file_.first_block(fiber), count = file_.block_count(fiber), bb = h.block_bytes();
    thread_local std::vector<float> xyz;
    xyz.resize(3 * std::size_t(h.points_per_block));
    for (std::uint64_t b = 0; b < count; ++b) {
        if (!has_bit(near, first + b)) continue;
        const std::uint8_t* block = blocks + b * bb;
        // A block is decoded (alone: its flags say whose last block it is)
        // only where its bound from the headers may meet the region.
        const Sphere sphere = block_bounding_sphere(h, block);
        const bool with_next = b + 1 < count && max_join_ >= 0;
        const Sphere next = with_next ? block_bounding_sphere(h, block + bb) : Sphere{};
        if (!detail::bound_may_meet(r, detail::block_bound(sphere, with_next ? &next : nullptr, max_join_))) continue;
        const std::size_t n = decode_blocks(ctx, block, 1, xyz.data());
        blocks_decoded_.fetch_add(1, std::memory_order_relaxed);
        for (std::size_t p = 0; p < n; ++p)
            if (r.contains({xyz[3 * p], xyz[3 * p + 1], xyz[3 * p + 2]})) return true;
    }
    return false;
}

bool FiberRegionTest::keeps_by_blocks(std::uint64_t fiber, const std::uint8_t* blocks, const DecodeContext& ctx) const {
    const std::uint64_t first = file_.first_block(fiber), end = first + file_.block_count(fiber);
    // Anchors first: an exclude region one meets drops the fiber before
    // anything is decoded.
    for (std::size_t i = 0; i < exclude_.size(); ++i)
        if (anchor_in(exclude_[i], near_exclude_[i], fiber, blocks)) return false;
    for (std::size_t i = 0; i < include_.size(); ++i)
        if (!any_bit(inside_include_[i], first, end) && !anchor_in(include_[i], near_include_[i], fiber, blocks) &&
            !point_in(include_[i], near_include_[i], fiber, blocks, ctx))
            return false;
    for (std::size_t i = 0; i < exclude_.size(); ++i)
        if (point_in(exclude_[i], near_exclude_[i], fiber, blocks, ctx)) return false;
    return true;
}

void FiberRegionTest::decide(std::uint64_t f0, std::uint64_t f1, const DecodeContext& ctx, std::uint8_t* kept,
                             bool read_kept, std::vector<std::uint8_t>& blocks) const {
    thread_local std::vector<Fate> fates;
    fates.resize(f1 - f0);
    for (std::uint64_t f = f0; f < f1; ++f) {
        fates[f - f0] = fate_by_index(f);
        kept[f - f0] = fates[f - f0] == Fate::kept;
    }
    // The blocks of the fibers to read, a run of consecutive fibers at a
    // time, each at its place from f0's first block on.
    auto to_read = [&](std::uint64_t f) {
        return fates[f - f0] == Fate::undecided || (read_kept && fates[f - f0] == Fate::kept);
    };
    const std::uint64_t b0 = file_.first_block(f0), bb = file_.header().block_bytes();
    blocks.resize((file_.block_end(f1) - b0) * bb);
    for (std::uint64_t f = f0; f < f1;) {
        std::uint64_t e = f + 1;
        if (to_read(f)) {
            while (e < f1 && to_read(e)) ++e;
            const std::uint64_t first = file_.first_block(f);
            if (file_.block_end(e) > first) {
                file_.read_blocks(first, file_.block_end(e) - first, blocks.data() + (first - b0) * bb);
                blocks_read_.fetch_add(file_.block_end(e) - first, std::memory_order_relaxed);
            }
        }
        f = e;
    }
    for (std::uint64_t f = f0; f < f1; ++f) {
        if (fates[f - f0] != Fate::undecided) continue;
        kept[f - f0] = keeps_by_blocks(f, blocks.data() + (file_.first_block(f) - b0) * bb, ctx);
    }
}

std::vector<std::uint64_t> FiberRegionTest::kept_fibers(std::span<const FiberRange> candidates, unsigned threads,
                                                        SelectionStats* stats) const {
    const Parts parts = parts_of(file_, candidates);
    const std::uint64_t read_before = blocks_read_, decoded_before = blocks_decoded_;
    std::vector<std::uint8_t> kept(parts.flag_at.back());
    const DecodeContext ctx(file_);
    parallel_for(parts.size(), threads, [&](std::size_t p) {
        thread_local std::vector<std::uint8_t> blocks;
        decide(parts.first[p], parts.end[p], ctx, kept.data() + parts.flag_at[p], false, blocks);
    });
    std::vector<std::uint64_t> out;
    for (std::size_t p = 0; p < parts.size(); ++p)
        for (std::uint64_t f = parts.first[p]; f < parts.end[p]; ++f)
            if (kept[parts.flag_at[p] + f - parts.first[p]]) out.push_back(f);
    if (stats) {
        *stats = {};
        stats->fibers = stats->runs = out.size();
        for (const std::uint64_t f : out) stats->blocks += file_.block_count(f);
        stats->blocks_read = blocks_read_ - read_before, stats->blocks_decoded = blocks_decoded_ - decoded_before;
        stats->blocks_tested = stats->blocks_read;  // their anchors and bounds looked at
    }
    return out;
}

std::optional<std::vector<SelectedRun>> kept_fiber_runs(const FftFile& file, const BlockIndex& index, const Query& q,
                                                        unsigned threads, SelectionStats* stats) {
    detail::check_query(q);
    const bool regions_alone = q.roi_mode == RoiMode::fibers && !(q.include.empty() && q.exclude.empty()) &&
                               !q.min_length_mm && !q.max_length_mm && !q.random_fraction && !q.ends_only &&
                               !q.inverse && q.skip == 0 && !q.number && !q.view;
    if (!regions_alone) return std::nullopt;
    const FiberRegionTest test(file, index, q);
    if (!test.kept_fibers_is_faster(threads)) return std::nullopt;
    // The query's ranges within the file, sorted and merged, as select() takes them.
    const std::uint64_t fibers = file.header().fibers;
    std::vector<FiberRange> candidates;
    if (q.fibers.empty() && fibers > 0) candidates.push_back({0, fibers - 1});
    for (const FiberRange& r : q.fibers)
        if (r.first < fibers) candidates.push_back({r.first, std::min(r.last, fibers - 1)});
    std::sort(candidates.begin(), candidates.end(),
              [](const FiberRange& a, const FiberRange& b) { return a.first < b.first; });
    std::vector<FiberRange> merged;
    for (const FiberRange& r : candidates) {
        if (!merged.empty() && r.first <= merged.back().last + 1)
            merged.back().last = std::max(merged.back().last, r.last);
        else
            merged.push_back(r);
    }
    std::vector<SelectedRun> runs;
    for (const std::uint64_t f : test.kept_fibers(merged, threads, stats))
        runs.push_back({f, file.first_block(f), file.block_count(f), 0});
    return runs;
}

std::uint64_t FiberRegionTest::decode_kept_into(std::span<const FiberRange> candidates, std::span<float> xyz,
                                                std::vector<std::uint64_t>& offsets, std::vector<std::uint64_t>& fibers,
                                                unsigned threads) const {
    const Parts parts = parts_of(file_, candidates);
    const FftHeader& h = file_.header();
    std::vector<std::uint8_t> kept(parts.flag_at.back());
    std::vector<std::vector<std::uint32_t>> kept_points(parts.size());  // per part, per kept fiber
    detail::OrderedEnds ends(parts.size());
    const DecodeContext ctx(file_);
    detail::parallel_parts(ends, threads, [&](std::size_t p) {
        const std::uint64_t f0 = parts.first[p], f1 = parts.end[p], b0 = file_.first_block(f0);
        std::uint8_t* k = kept.data() + parts.flag_at[p];
        thread_local std::vector<std::uint8_t> blocks;
        decide(f0, f1, ctx, k, true, blocks);
        std::uint64_t points = 0;
        for (std::uint64_t f = f0; f < f1; ++f) {
            if (!k[f - f0]) continue;
            std::uint32_t n = 0;
            for (std::uint64_t b = file_.first_block(f); b < file_.block_end(f + 1); ++b)
                n += block_flags(h, blocks.data() + (b - b0) * h.block_bytes()).point_count;
            kept_points[p].push_back(n);
            points += n;
        }
        const std::uint64_t base = ends.publish(p, points);
        if (base == detail::OrderedEnds::kFailed) return;  // a part before failed: its error is the one reported
        if (3 * (base + points) > xyz.size())
            throw Error(Errc::invalid_argument, "decode_kept_into: " + file_.path() +
                                                    "'s kept fibers hold more points than the " +
                                                    std::to_string(xyz.size() / 3) + " the buffer has room for");
        // Runs of consecutive kept fibers, each one decode.
        float* out = xyz.data() + 3 * base;
        for (std::uint64_t f = f0; f < f1;) {
            std::uint64_t e = f + 1;
            if (k[f - f0]) {
                while (e < f1 && k[e - f0]) ++e;
                const std::uint64_t first = file_.first_block(f);
                out += 3 * decode_blocks(ctx, blocks.data() + (first - b0) * h.block_bytes(),
                                         file_.block_end(e) - first, out);
            }
            f = e;
        }
    });
    fibers.clear();
    offsets.assign(1, 0);
    for (std::size_t p = 0; p < parts.size(); ++p) {
        std::size_t i = 0;
        for (std::uint64_t f = parts.first[p]; f < parts.end[p]; ++f)
            if (kept[parts.flag_at[p] + f - parts.first[p]]) {
                fibers.push_back(f);
                offsets.push_back(offsets.back() + kept_points[p][i++]);
            }
    }
    return offsets.back();
}

}  // namespace fiblet
