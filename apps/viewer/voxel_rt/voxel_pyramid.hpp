// The layout of the trace's mip pyramids of "anything here" flags, which
// its empty-space skipping walks (empty_space_skipping.glsl): level 0 the
// grid's n³ voxels, level l + 1 one cell per 2³ cells of level l, down to
// one cell or an odd side (a cell of an odd level would have no whole set
// of children). Every level lies in one buffer, finest first, x fastest.
// Two pyramids use it: the culling's visibility (voxel_culling.hpp, per
// camera) and the structure's occupancy (voxel_structure.hpp, which leaves
// level 0 out: the cells' counts are that level).
#pragma once

#include <cstdint>
#include <vector>

namespace fiblet::viewer::voxel_rt {

// The most levels a pyramid holds (--grid 512: 512 .. 1); the trace's
// uniform arrays have this size (VRT_PYRAMID_LEVELS).
inline constexpr int kMaxPyramidLevels = 10;

struct PyramidLayout {
    std::vector<std::uint32_t> level_offset;  // per level, in cells from the finest
    std::uint64_t cells = 0;                  // every level together
};

inline PyramidLayout pyramid_layout(int n) {
    PyramidLayout p;
    for (int side = n; side >= 1 && int(p.level_offset.size()) < kMaxPyramidLevels; side /= 2) {
        p.level_offset.push_back(std::uint32_t(p.cells));
        p.cells += std::uint64_t(side) * std::uint64_t(side) * std::uint64_t(side);
        if (side % 2) break;
    }
    return p;
}

}  // namespace fiblet::viewer::voxel_rt
