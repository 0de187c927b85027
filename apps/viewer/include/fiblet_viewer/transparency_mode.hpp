// How a frame with opacity < 1 orders what it blends (RenderOptions::
// transparency): the modes of docs/viewer.md's transparency section.
#pragma once

#include <optional>
#include <string>

namespace fiblet::viewer {

enum class TransparencyMode {
    sorted,    // ~1 mm chunks of the decoded blocks sorted back to front on the GPU (sorted_chunks.hpp), any style
    voxlines,  // the Voxlines paper: 10 mm voxels back to front, precomputed axis orders inside (voxlines.hpp); lines only, other styles draw sorted
    unsorted,  // plain blending in the order the blocks are drawn
};

const char* transparency_mode_name(TransparencyMode mode);
std::optional<TransparencyMode> parse_transparency_mode(const std::string& name);
std::string transparency_mode_names();  // "voxlines, sorted, unsorted"

}  // namespace fiblet::viewer
