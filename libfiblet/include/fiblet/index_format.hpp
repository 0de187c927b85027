// fiblet — which version of the block index (BIDX chunk,
// formats/fft-index.md) a writer produces: compress (CompressOptions) and
// extract's subset files (write_fft_subset). Every version is read.
#pragma once

#include <cstdint>

namespace fiblet {

// The value is the chunk's version number.
// group_boxes (2, the default): a box per group of up to 8 blocks of a
// fiber, loaded in a few ms (the medium file: 6 ms). block_boxes (4): a box
// per block, rANS-coded: about 3x fewer candidate blocks for a small
// region, about 5x slower to load (32 ms). Version 3 (a box per block,
// range-coded) is read, no longer written.
enum class BlockIndexFormat : std::uint32_t { group_boxes = 2, block_boxes = 4 };
inline constexpr BlockIndexFormat kDefaultBlockIndexFormat = BlockIndexFormat::group_boxes;

}  // namespace fiblet
