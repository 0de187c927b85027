#include "voxel_rt/voxel_rt_programs.hpp"

#include <string>

#include "fiblet/error.hpp"
#include "gl/shader_program.hpp"
#include "voxel_rt/voxel_rt_bindings.hpp"

namespace fiblet::viewer::voxel_rt {

VoxelRtPrograms::VoxelRtPrograms() {
    GLint bindings = 0;
    glGetIntegerv(GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS, &bindings);
    if (bindings <= GLint(binding::kHighest))
        throw Error(Errc::unsupported, "the GL driver offers " + std::to_string(bindings) +
                                           " shader storage buffer bindings; the voxel ray tracer needs " +
                                           std::to_string(binding::kHighest + 1));
    const std::string defines = voxel_rt_defines();
    voxelize = build_program({"voxelize_capsules.comp.glsl"}, defines);
    scan = build_program({"scan_counts.comp.glsl"}, defines);
    occupancy = build_program({"occupancy_volume.comp.glsl"}, defines);
    ambient_occlusion = build_program({"ambient_occlusion.comp.glsl"}, defines);
    trace = build_program({"full_screen.vert.glsl", "trace.frag.glsl"}, defines);
    cull = build_program({"cull_voxels.comp.glsl"}, defines);
    occupied_pyramid = build_program({"occupied_pyramid.comp.glsl"}, defines);
    chords = build_program({"chord_segments.comp.glsl"}, defines);
}

}  // namespace fiblet::viewer::voxel_rt
