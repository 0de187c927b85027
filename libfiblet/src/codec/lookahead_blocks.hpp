// Internal: the lookahead search (LookaheadSearch; depth 1 is the default
// effort's first search) for many 8-bit blocks at once; depth 1 one block per
// SIMD lane, at the level greedy_blocks.hpp chooses. Per point every lane
// scores the aimed code and its eight neighbours by their own error plus the
// error of the greedy step after them, all nine at once, where the scalar
// search tries its rivals one by one with branch and bound; the winner is
// the one the scalar search keeps (the smallest sum; on a tie the aimed
// code, then the rival of smaller own error, then the earlier neighbour),
// so the codes and decoded points are the same bits as LookaheadSearch's
// (tests/block_lanes_test.cpp).
#pragma once

#include "codec/greedy_blocks.hpp"

namespace fiblet::detail {

// LookaheadSearch(cb, step, depth).run(...) for every block of the batch:
// depth 1 at simd_level(), other depths (and where the lookup table is not
// usable) in scalar lanes.
void lookahead_blocks(const Codebook8& cb, float step, std::size_t depth, const GreedyBatch& batch);
// The same at a given level (which must be supported).
void lookahead_blocks(const Codebook8& cb, float step, std::size_t depth, const GreedyBatch& batch, SimdLevel level);

}  // namespace fiblet::detail
