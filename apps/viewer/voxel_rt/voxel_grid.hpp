// The voxel ray tracer's grid: a cube of n³ voxels around the scene (its
// longest side plus the capsules' radius), as the paper's 128³.
#pragma once

#include <algorithm>
#include <array>

#include "scene/gpu_scene.hpp"

namespace fiblet::viewer::voxel_rt {

struct VoxelGrid {
    int n = 128;
    std::array<float, 3> origin{0, 0, 0};  // world mm of the corner
    float voxel_mm = 1;

    // World mm to voxel units (voxel v covers [v, v + 1)).
    std::array<float, 3> to_grid(const std::array<float, 3>& p) const {
        return {(p[0] - origin[0]) / voxel_mm, (p[1] - origin[1]) / voxel_mm, (p[2] - origin[2]) / voxel_mm};
    }
};

inline VoxelGrid grid_around(const SceneBounds& b, int n, float radius_mm) {
    VoxelGrid g;
    g.n = n;
    const float side = std::max({b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z}) + 2 * radius_mm;
    // A little more, so that no capsule touches the grid's faces.
    g.voxel_mm = std::max(side, 1e-3f) * 1.01f / float(n);
    const Vec3f c = b.center();
    const float half = 0.5f * g.voxel_mm * float(n);
    g.origin = {c.x - half, c.y - half, c.z - half};
    return g;
}

}  // namespace fiblet::viewer::voxel_rt
