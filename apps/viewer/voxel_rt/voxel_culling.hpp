// Visibility culling of the voxel ray tracer's voxels (cull_voxels.comp.glsl):
// the eroded occupancy once per structure, then per camera a march from
// each occupied voxel towards the eye and the "any child visible" pyramid.
// The trace then skips invisible voxels, and invisible 4³ blocks at once.
// Opaque frames only: behind a transparent surface nothing is hidden, and
// shadow rays ignore it (a voxel the eye does not see still casts shadows).
#pragma once

#include <cstdint>
#include <vector>

#include "fiblet/view.hpp"
#include "gl_objects.hpp"
#include "voxel_rt/voxel_rt_programs.hpp"
#include "voxel_rt/voxel_structure.hpp"

namespace fiblet::viewer::voxel_rt {

class VoxelCulling {
public:
    // Level of the pyramid whose blocks the trace skips (2: 4³ voxels).
    static constexpr int kSkipLevel = 2;
    // Summed occupancy that makes a voxel full (then solid when its six
    // face neighbours are full too).
    static constexpr float kSolidOccupancy = 1.0f;

    VoxelCulling(const VoxelRtPrograms& programs, const VoxelStructure& structure);

    // Recomputes the visibility for `camera` (nothing when it is the last one).
    void update(const VoxelRtPrograms& programs, const VoxelStructure& structure, const Camera& camera);

    // Binds the pyramid and sets the trace's culling uniforms on `program`.
    void bind(const GlProgram& program) const;

    // Occupied and visible voxels of level 0 (tests, statistics).
    std::uint64_t visible_voxels() const;
    double last_update_ms() const { return last_update_ms_; }

private:
    int n_;
    std::vector<std::uint32_t> level_offset_;  // per level, in voxels
    GlBuffer solid_, visible_;
    bool has_camera_ = false;
    Camera camera_{};
    double last_update_ms_ = 0;
};

}  // namespace fiblet::viewer::voxel_rt
