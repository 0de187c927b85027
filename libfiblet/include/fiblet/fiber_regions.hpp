// fiblet — fibers-mode regions (tckedit -include / -exclude) decided on all
// threads: kept_fibers() decides most fibers from the index and the
// blocks' anchors and decodes only the blocks that may still meet a
// region; decode_kept_into() also decodes the kept fibers in the same job
// (Python's roi=); kept_fiber_runs() gives the CLI's extract to .fft its
// runs. kept_fibers_is_faster() is the rule that chooses between these and
// select()'s index-driven passes.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "fiblet/block_index.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/select.hpp"

namespace fiblet {

// The blocks the index puts near region `r` (a bitmap of index.blocks()
// bits; conservative: a block with a point in the region is always set),
// and in `inside` those wholly in it (see BlockIndex::blocks_near_sphere).
std::vector<std::uint64_t> blocks_near(const BlockIndex& index, const Region& r,
                                       std::vector<std::uint64_t>* inside = nullptr);

// The regions of `query` (include, exclude; its other criteria are not
// looked at), with the blocks the index puts near each: a fiber's points
// are tested only in those blocks (the index is conservative, so the
// answer is select()'s).
class FiberRegionTest {
public:
    FiberRegionTest(const FftFile& file, const BlockIndex& index, const Query& query);

    // The fibers among `candidates` (ascending, disjoint ranges) with a point
    // in every include region and none in an exclude region (a fiber without
    // points: never), ascending, without decoding what the index and the blocks'
    // anchors decide: an include region with no block near it drops a
    // fiber, a block wholly inside one or an anchor in it (a block's first
    // two points, stored exactly) meets it; of the fibers left, only the
    // blocks whose bounds from the headers may meet a region are decoded.
    // On `threads` threads (0: all cores). Error{invalid_argument} for
    // ranges out of order, overlapping or past the end.
    // With `stats`: fibers, runs and blocks kept, blocks read and decoded.
    std::vector<std::uint64_t> kept_fibers(std::span<const FiberRange> candidates, unsigned threads = 0,
                                           SelectionStats* stats = nullptr) const;

    // kept_fibers(), with the kept fibers decoded into xyz, each as soon as
    // it is decided (its blocks read once): fibers gets their indices,
    // offsets[i] the first point of fibers[i] (and the number of points at
    // the end), which is returned. xyz needs room for the points of the
    // candidates' blocks full (points_per_block each) only where the kept
    // fibers hold fewer: Error{invalid_argument} when it is too small,
    // before anything is written past it.
    std::uint64_t decode_kept_into(std::span<const FiberRange> candidates, std::span<float> xyz,
                                   std::vector<std::uint64_t>& offsets, std::vector<std::uint64_t>& fibers,
                                   unsigned threads = 0) const;

    // Whether kept_fibers() on `threads` threads (0: all cores) beats
    // select()'s passes, which decode the blocks near a region then the
    // kept fibers on one thread: always with two threads or more (it is
    // also faster on the smallest regions), on one when the most selective
    // include region (or, with none, the exclude regions) has blocks near
    // it in more than a fifth of the file (measured on the medium
    // tractogram: docs/select.md). From the bitmaps above: no second query
    // of the index.
    bool kept_fibers_is_faster(unsigned threads) const;

private:
    enum class Fate : std::uint8_t { dropped, kept, undecided };
    Fate fate_by_index(std::uint64_t fiber) const;
    bool anchor_in(const Region& r, const std::vector<std::uint64_t>& near, std::uint64_t fiber,
                   const std::uint8_t* blocks) const;
    bool point_in(const Region& r, const std::vector<std::uint64_t>& near, std::uint64_t fiber,
                  const std::uint8_t* blocks, const DecodeContext& ctx) const;
    bool keeps_by_blocks(std::uint64_t fiber, const std::uint8_t* blocks, const DecodeContext& ctx) const;
    // Fibers [f0, f1): kept[f - f0] = 1 for those kept; `blocks` gets the
    // blocks of the fibers the index leaves undecided (and, with read_kept,
    // those it keeps) from f0's first block on.
    void decide(std::uint64_t f0, std::uint64_t f1, const DecodeContext& ctx, std::uint8_t* kept, bool read_kept,
                std::vector<std::uint8_t>& blocks) const;
    const FftFile& file_;
    std::vector<Region> include_, exclude_;
    // Bitmaps of blocks: near each region, and wholly inside each include region.
    std::vector<std::vector<std::uint64_t>> near_include_, inside_include_, near_exclude_;
    float max_join_;  // BlockIndex::max_join()
    // Blocks read and decoded by the calls so far (for SelectionStats).
    mutable std::atomic<std::uint64_t> blocks_read_{0}, blocks_decoded_{0};
};

// select_runs() of a query of fibers-mode regions alone (include and
// exclude, over its fiber ranges or every fiber: no other criterion), by
// FiberRegionTest::kept_fibers on `threads` threads where its rule says it
// is faster: every kept fiber one run of all its blocks. nullopt for other
// queries and where select_runs() is faster. Error{invalid_argument} for a
// query select() refuses.
std::optional<std::vector<SelectedRun>> kept_fiber_runs(const FftFile& file, const BlockIndex& index,
                                                        const Query& query, unsigned threads = 0,
                                                        SelectionStats* stats = nullptr);

}  // namespace fiblet
