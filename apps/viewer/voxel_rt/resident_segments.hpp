// Every block of a scene decoded once on the GPU into one buffer (the
// voxel ray tracer needs all segments resident: its fragment lists point
// into it). The layout is BlockDecoder's slots, block b in slot b.
//
// Memory: (points per block + 1) × 16 bytes per block (976 B for 60 points,
// ≈ 16.3 B per segment), in one storage buffer; a file whose blocks exceed
// the driver's largest storage buffer (llvmpipe: 128 MiB, ≈ 137 k blocks,
// 8 M segments) is refused with fiblet::Error{unsupported} rather than
// drawn in part.
#pragma once

#include "gl_objects.hpp"
#include "gpu_programs.hpp"
#include "gpu_scene.hpp"
#include "voxel_rt/voxel_structure.hpp"

namespace fiblet::viewer::voxel_rt {

class SceneSegments {
public:
    SceneSegments(const GpuScene& scene, const GpuPrograms& programs);
    ResidentSegments segments() const { return {points_.get(), slots_, per_slot_, scene_}; }
    double decode_ms() const { return decode_ms_; }

private:
    const GpuScene* scene_;
    GlBuffer points_;
    std::uint32_t slots_ = 0, per_slot_ = 1;
    double decode_ms_ = 0;
};

}  // namespace fiblet::viewer::voxel_rt
