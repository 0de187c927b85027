#include "voxel_rt/chord_occlusion.hpp"

#include <algorithm>

#include "gl/gpu_bindings.hpp"
#include "gl/shader_program.hpp"
#include "voxel_rt/voxel_rt_bindings.hpp"

namespace fiblet::viewer {

void set_occlusion_uniforms(const GlProgram& p, const OcclusionVolume* v) {
    const GLuint id = p.get();
    glProgramUniform1i(id, uniform(p, "uOcclusionOn"), v ? 1 : 0);
    if (!v) return;
    glProgramUniform3f(id, uniform(p, "uOcclusionOrigin"), v->grid.origin[0], v->grid.origin[1], v->grid.origin[2]);
    glProgramUniform1f(id, uniform(p, "uOcclusionVoxelMm"), v->grid.voxel_mm);
    glProgramUniform1f(id, uniform(p, "uOcclusionGridN"), float(v->grid.n));
    glBindTextureUnit(7, v->texture);
}

namespace voxel_rt {

ChordOcclusion::ChordOcclusion(const VoxelRtPrograms& programs, const GpuScene& scene, const VoxelGrid& grid,
                               float radius_mm) {
    const std::uint32_t blocks = scene.block_count();
    chords_ = make_buffer(GLsizeiptr(std::max(blocks, 1u)) * 32, nullptr, 0);
    const GlProgram& p = programs.chords;
    glUseProgram(p.get());
    scene.bind(p);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kPoints, chords_.get());
    const std::uint32_t groups = (blocks + 63) / 64, x = std::min(std::max(groups, 1u), 65535u);
    glDispatchCompute(x, (groups + x - 1) / x, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    // One chord per slot, every slot valid (no scene: no per-block segment counts).
    structure_ = std::make_unique<VoxelStructure>(programs, grid, ResidentSegments{chords_.get(), blocks, 1, nullptr},
                                                  radius_mm, true);
}

}  // namespace voxel_rt
}  // namespace fiblet::viewer
