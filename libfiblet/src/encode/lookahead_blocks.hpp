// Internal: the lookahead search (LookaheadSearch: depth 1 is the default
// effort's first search, depth 2 its retry and length tails) for many 8-bit
// blocks at once, one block per SIMD lane at the level greedy_blocks.hpp
// chooses. Per point every lane scores the aimed code by its own error plus
// the errors of the greedy steps after it, then tries its rivals
// (LookaheadRivals) in the scalar search's order, cheapest own error first
// while below the lane's best, in rounds until no lane has one left; the
// winner is the one the scalar search keeps, so the codes and decoded points
// are the same bits as LookaheadSearch's (tests/block_lanes_test.cpp).
#pragma once

#include "encode/greedy_blocks.hpp"

namespace fiblet::detail {

// LookaheadSearch(cb, step, depth, rivals).run(...) for every block of the
// batch: depths 1 and 2 at simd_level(), other depths (and where the lookup
// table is not usable) in scalar lanes.
void lookahead_blocks(const Codebook8& cb, float step, std::size_t depth, LookaheadRivals rivals,
                      const GreedyBatch& batch);
// The same at a given level (which must be supported).
void lookahead_blocks(const Codebook8& cb, float step, std::size_t depth, LookaheadRivals rivals,
                      const GreedyBatch& batch, SimdLevel level);

}  // namespace fiblet::detail
