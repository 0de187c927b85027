// Occlusion without decoding: the occupancy and ambient occlusion of a
// scene built from one chord per block (its first point to the next block's
// first point, the coarse level of detail's segment) instead of every
// decoded segment: 60× fewer capsules, and nothing decoded. What --ao
// shades the rasterized styles with.
#pragma once

#include <memory>

#include "gl/gl_objects.hpp"
#include "scene/gpu_scene.hpp"
#include "voxel_rt/voxel_rt_programs.hpp"
#include "voxel_rt/voxel_structure.hpp"

namespace fiblet::viewer {

// An ambient occlusion volume and its grid, as occlusion_lookup.glsl reads it.
struct OcclusionVolume {
    GLuint texture = 0;
    voxel_rt::VoxelGrid grid;
};

// Sets occlusion_lookup.glsl's uniforms of `program` and binds the volume
// (texture unit 7); null: occlusion off.
void set_occlusion_uniforms(const GlProgram& program, const OcclusionVolume* volume);

namespace voxel_rt {

class ChordOcclusion {
public:
    ChordOcclusion(const VoxelRtPrograms& programs, const GpuScene& scene, const VoxelGrid& grid, float radius_mm);
    const VoxelStructure& structure() const { return *structure_; }
    OcclusionVolume volume() const { return {structure_->ambient_occlusion_texture(), structure_->grid()}; }

private:
    GlBuffer chords_;
    std::unique_ptr<VoxelStructure> structure_;
};

}  // namespace voxel_rt
}  // namespace fiblet::viewer
