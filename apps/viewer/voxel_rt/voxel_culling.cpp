#include "voxel_rt/voxel_culling.hpp"

#include <chrono>

#include "gl/shader_program.hpp"
#include "voxel_rt/voxel_rt_bindings.hpp"

namespace fiblet::viewer::voxel_rt {

namespace {
bool same_camera(const Camera& a, const Camera& b) {
    return a.position.x == b.position.x && a.position.y == b.position.y && a.position.z == b.position.z;
}
void dispatch_cube(int n) {
    const GLuint g = GLuint((n + 3) / 4);
    glDispatchCompute(g, g, g);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}
}  // namespace

VoxelCulling::VoxelCulling(const VoxelRtPrograms& programs, const VoxelStructure& structure)
    : n_(structure.grid().n), pyramid_(pyramid_layout(n_)) {
    const std::uint64_t voxels = std::uint64_t(n_) * std::uint64_t(n_) * std::uint64_t(n_);
    solid_ = make_buffer(GLsizeiptr(voxels * 4), nullptr, 0);
    visible_ = make_buffer(GLsizeiptr(pyramid_.cells * 4), nullptr, 0);
    const GlProgram& p = programs.cull;
    glUseProgram(p.get());
    structure.bind();
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kSolid, solid_.get());
    glProgramUniform1ui(p.get(), uniform(p, "uStage"), 0);
    glProgramUniform1ui(p.get(), uniform(p, "uGridN"), GLuint(n_));
    glProgramUniform1f(p.get(), uniform(p, "uSolidOccupancy"), kSolidOccupancy);
    dispatch_cube(n_);
}

void VoxelCulling::update(const VoxelRtPrograms& programs, const VoxelStructure& structure, const Camera& camera) {
    if (has_camera_ && same_camera(camera, camera_)) return;
    glFinish();
    const auto t0 = std::chrono::steady_clock::now();
    const GlProgram& p = programs.cull;
    const GLuint id = p.get();
    glUseProgram(id);
    structure.bind();
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kSolid, solid_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kVisible, visible_.get());
    const VoxelGrid& g = structure.grid();
    glProgramUniform1ui(id, uniform(p, "uGridN"), GLuint(n_));
    glProgramUniform3f(id, uniform(p, "uGridOrigin"), g.origin[0], g.origin[1], g.origin[2]);
    glProgramUniform1f(id, uniform(p, "uVoxelMm"), g.voxel_mm);
    glProgramUniform3f(id, uniform(p, "uCameraPosition"), camera.position.x, camera.position.y, camera.position.z);
    glProgramUniform1ui(id, uniform(p, "uStage"), 1);
    dispatch_cube(n_);
    glProgramUniform1ui(id, uniform(p, "uStage"), 2);
    const std::vector<std::uint32_t>& offset = pyramid_.level_offset;
    for (std::size_t level = 1; level < offset.size(); ++level) {
        const int n = n_ >> level;
        glProgramUniform1ui(id, uniform(p, "uLevelN"), GLuint(n));
        glProgramUniform1ui(id, uniform(p, "uLevelOffset"), offset[level]);
        glProgramUniform1ui(id, uniform(p, "uChildOffset"), offset[level - 1]);
        dispatch_cube(n);
    }
    glFinish();
    last_update_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    has_camera_ = true, camera_ = camera;
}

void VoxelCulling::bind(const GlProgram& p) const {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kVisible, visible_.get());
    glProgramUniform1i(p.get(), uniform(p, "uCulling"), 1);
}

std::uint64_t VoxelCulling::visible_voxels() const {
    std::vector<std::uint32_t> v(std::size_t(n_) * std::size_t(n_) * std::size_t(n_));
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(visible_.get(), 0, GLsizeiptr(v.size() * 4), v.data());
    std::uint64_t count = 0;
    for (auto x : v) count += x;
    return count;
}

}  // namespace fiblet::viewer::voxel_rt
