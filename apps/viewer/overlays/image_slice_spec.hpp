// A slice of an image's voxel grid, "axis:index" on the command line (axis
// x, y or z of the voxel grid, or 0, 1, 2), and where it lies in the world.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "fiblet/image.hpp"
#include "fiblet_viewer/scene_sources.hpp"

namespace fiblet::viewer {

// The index the slice has in `image` (the middle when unset); throws
// fiblet::Error{invalid_argument} when it lies outside the grid.
std::int64_t slice_index(const SliceSpec& s, const Image& image, const char* option);

// The slice's plane in world mm: unit normal n and offset d (n·x = d for
// the voxel centres of the slice).
struct WorldPlane {
    std::array<double, 3> normal;
    double offset;
};
WorldPlane slice_plane(const Image& image, int axis, std::int64_t index);

}  // namespace fiblet::viewer
