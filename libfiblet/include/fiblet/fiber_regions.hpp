// fiblet — fibers-mode regions (tckedit -include / -exclude) tested on
// fibers already decoded, for callers that decode a whole range anyway (all
// threads, the fast path) instead of select()'s index-driven passes; and
// the rule that chooses between the two (FiberRegionTest::full_decode_is_faster).
#pragma once

#include <cstdint>
#include <vector>

#include "fiblet/block_index.hpp"
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
    // Whether fiber `fiber` of the file, decoded as xyz[0, 3 * points), has a
    // point in every include region and none in an exclude region (a fiber
    // without points: never).
    bool keeps(std::uint64_t fiber, const float* xyz, std::uint64_t points) const;

    // Whether decoding every fiber (on all threads) and testing their points
    // here beats select()'s passes, which decode the blocks near a region
    // then the kept fibers on one thread: when the most selective include
    // region (or, with none, the exclude regions) has blocks near it in more
    // than a quarter of the file (measured on the medium tractogram:
    // docs/ecosystem.md). From the bitmaps above: no second query of the index.
    bool full_decode_is_faster() const;

private:
    bool meets(const Region& r, const std::vector<std::uint64_t>& near, const std::vector<std::uint64_t>* inside,
               std::uint64_t fiber, const float* xyz, std::uint64_t points) const;
    const FftFile& file_;
    std::vector<Region> include_, exclude_;
    // Bitmaps of blocks: near each region, and wholly inside each include region.
    std::vector<std::vector<std::uint64_t>> near_include_, inside_include_, near_exclude_;
};

}  // namespace fiblet
