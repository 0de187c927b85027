// Visibility culling of the voxel ray tracer's voxels (cull_voxels.comp.glsl):
// the eroded occupancy once per structure, then per camera a march from
// each occupied voxel towards the eye and the "any child visible" pyramid
// (voxel_pyramid.hpp). The trace then skips invisible voxels, and invisible
// cells of every level of the pyramid at once (empty_space_skipping.glsl).
// Opaque frames only: behind a transparent surface nothing is hidden, and
// shadow rays ignore it (a voxel the eye does not see still casts shadows).
#pragma once

#include <cstdint>
#include <vector>

#include "fiblet/view.hpp"
#include "gl/gl_objects.hpp"
#include "voxel_rt/voxel_pyramid.hpp"
#include "voxel_rt/voxel_rt_programs.hpp"
#include "voxel_rt/voxel_structure.hpp"

namespace fiblet::viewer::voxel_rt {

class VoxelCulling {
public:
    // Summed occupancy that makes a voxel full (then solid when its six
    // face neighbours are full too).
    static constexpr float kSolidOccupancy = 1.0f;

    VoxelCulling(const VoxelRtPrograms& programs, const VoxelStructure& structure);

    // Recomputes the visibility for `camera` (nothing when it is the last one).
    void update(const VoxelRtPrograms& programs, const VoxelStructure& structure, const Camera& camera);

    // Binds the pyramid and turns culling on in `program` (the structure
    // sets the pyramid's layout, which both share).
    void bind(const GlProgram& program) const;

    // Occupied and visible voxels of level 0 (tests, statistics).
    std::uint64_t visible_voxels() const;
    double last_update_ms() const { return last_update_ms_; }

private:
    int n_;
    PyramidLayout pyramid_;
    GlBuffer solid_, visible_;
    bool has_camera_ = false;
    Camera camera_{};
    double last_update_ms_ = 0;
};

}  // namespace fiblet::viewer::voxel_rt
