#include "voxel_rt/voxel_structure.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "fiblet/error.hpp"
#include "gl/shader_program.hpp"
#include "voxel_rt/voxel_rt_bindings.hpp"

namespace fiblet::viewer::voxel_rt {

namespace {

// Voxels per prefix-sum chunk (walked by one invocation).
constexpr std::uint32_t kScanChunk = 256;

// Wall-clock milliseconds of `work` with the GL queue drained before and
// after (llvmpipe's timer queries do not measure compute).
template <class Work>
double timed(Work&& work) {
    glFinish();
    const auto t0 = std::chrono::steady_clock::now();
    work();
    glFinish();
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

int mip_levels(int n) {
    int levels = 1;
    while ((n >> levels) > 0) ++levels;
    return levels;
}

GlTexture make_volume(int n, int levels) {
    GLuint t = 0;
    glCreateTextures(GL_TEXTURE_3D, 1, &t);
    glTextureStorage3D(t, levels, GL_R16F, n, n, n);
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, levels > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
        glTextureParameteri(t, wrap, GL_CLAMP_TO_BORDER);
    const float border[4] = {0, 0, 0, 0};
    glTextureParameterfv(t, GL_TEXTURE_BORDER_COLOR, border);
    return GlTexture(t);
}

std::uint64_t voxel_count(const VoxelGrid& g) { return std::uint64_t(g.n) * std::uint64_t(g.n) * std::uint64_t(g.n); }

}  // namespace

void bind_segments(const GlProgram& p, const ResidentSegments& s, const VoxelGrid& g, float radius_mm) {
    const GLuint id = p.get();
    if (s.scene) s.scene->bind(p);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kPoints, s.points);
    // Unused parts' bindings hold part 0 (a binding must hold a buffer).
    for (unsigned part = 1; part < binding::kPointParts; ++part)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kMorePoints + part - 1,
                         part <= s.more_parts.size() ? s.more_parts[part - 1] : s.points);
    const bool split = !s.more_parts.empty();
    glProgramUniform1ui(id, uniform(p, "uPointParts"), GLuint(1 + s.more_parts.size()));
    glProgramUniform1ui(id, uniform(p, "uPointsPerPart"),
                        split ? GLuint(s.slots_per_part * (s.segments_per_slot + 1)) : 0xffffffffu);
    glProgramUniform1ui(id, uniform(p, "uGridN"), GLuint(g.n));
    glProgramUniform3f(id, uniform(p, "uGridOrigin"), g.origin[0], g.origin[1], g.origin[2]);
    glProgramUniform1f(id, uniform(p, "uVoxelMm"), g.voxel_mm);
    glProgramUniform1ui(id, uniform(p, "uSegmentSlots"), s.slots);
    glProgramUniform1ui(id, uniform(p, "uSegmentsPerSlot"), s.segments_per_slot);
    glProgramUniform1i(id, uniform(p, "uAllSegmentsValid"), s.scene ? 0 : 1);
    glProgramUniform1f(id, uniform(p, "uRadiusMm"), radius_mm);
    glProgramUniform1i(id, uniform(p, "uFiberRadii"), s.fiber_radii && s.scene && s.scene->has_fiber_radii() ? 1 : 0);
}

VoxelStructure::VoxelStructure(const VoxelRtPrograms& p, const VoxelGrid& grid, const ResidentSegments& s,
                               float radius_mm, bool ambient_occlusion, std::uint64_t part_bytes)
    : grid_(grid), part_bytes_(part_bytes) {
    const std::uint64_t voxels = voxel_count(grid_);
    cells_ = make_buffer(GLsizeiptr(voxels * 4), nullptr, 0);
    offsets_ = make_buffer(GLsizeiptr((voxels + 1) * 4), nullptr, 0);
    cursor_ = make_buffer(GLsizeiptr(voxels * 4), nullptr, 0);
    times_.count_ms = timed([&] { count_and_occupy(p, s, radius_mm); });
    times_.scan_ms = timed([&] { prefix_sum(p); });
    times_.fill_ms = timed([&] { fill_lists(p, s, radius_mm); });
    times_.occupancy_ms = timed([&] {
        build_occupancy(p);
        build_occupied_pyramid(p);
    });
    if (ambient_occlusion) times_.ambient_occlusion_ms = timed([&] { build_ambient_occlusion(p); });
    cursor_.reset();
}

void VoxelStructure::dispatch_segments(const GlProgram& p, const ResidentSegments& s) const {
    const std::uint64_t groups = (std::uint64_t(s.slots) * s.segments_per_slot + 63) / 64;
    if (groups == 0) return;
    const std::uint64_t x = std::min<std::uint64_t>(groups, 65535);
    glProgramUniform1ui(p.get(), uniform(p, "uSegmentBase"), 0);
    glDispatchCompute(GLuint(x), GLuint((groups + x - 1) / x), 1);
}

void VoxelStructure::count_and_occupy(const VoxelRtPrograms& p, const ResidentSegments& s, float radius_mm) {
    const GLuint zero = 0;
    glClearNamedBufferData(cells_.get(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glUseProgram(p.voxelize.get());
    bind_segments(p.voxelize, s, grid_, radius_mm);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kCells, cells_.get());
    glProgramUniform1ui(p.voxelize.get(), uniform(p.voxelize, "uPass"), 0);
    dispatch_segments(p.voxelize, s);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void VoxelStructure::prefix_sum(const VoxelRtPrograms& p) {
    const auto voxels = std::uint32_t(voxel_count(grid_));
    const std::uint32_t chunks = (voxels + kScanChunk - 1) / kScanChunk;
    const GlBuffer chunk_sums = make_buffer(GLsizeiptr(chunks + 1) * 4, nullptr, 0);
    const GLuint id = p.scan.get();
    glUseProgram(id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kCells, cells_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kOffsets, offsets_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kCursor, cursor_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kChunks, chunk_sums.get());
    glProgramUniform1ui(id, uniform(p.scan, "uVoxels"), voxels);
    glProgramUniform1ui(id, uniform(p.scan, "uChunk"), kScanChunk);
    for (GLuint stage : {0u, 1u, 2u}) {
        glProgramUniform1ui(id, uniform(p.scan, "uStage"), stage);
        glDispatchCompute(stage == 1 ? 1 : (chunks + 63) / 64, 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    }
    std::uint32_t total = 0;
    glGetNamedBufferSubData(offsets_.get(), GLintptr(voxels) * 4, 4, &total);
    fragments_count_ = total;
    // Parts of whole entries, each a buffer texture's worth at most.
    GLint texels = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &texels);
    std::uint64_t per_part = std::uint64_t(texels);
    if (part_bytes_) per_part = std::min(per_part, part_bytes_ / 4);
    per_part = std::max<std::uint64_t>(per_part, 1);
    const std::uint64_t entries = std::max<std::uint64_t>(total, 1);
    const std::uint64_t parts = (entries + per_part - 1) / per_part;
    if (parts > binding::kFragmentParts)
        throw Error(Errc::unsupported, "voxel-rt: the fragment lists need " + std::to_string((entries * 4) >> 20) +
                                           " MiB, over " + std::to_string(binding::kFragmentParts) +
                                           " of the driver's largest buffer textures (" +
                                           std::to_string((per_part * 4) >> 20) +
                                           " MiB each); use a smaller --grid or --radius");
    fragments_per_part_ = std::uint32_t(std::min(per_part, entries));
    for (std::uint64_t part = 0; part < parts; ++part) {
        const std::uint64_t count = std::min<std::uint64_t>(fragments_per_part_, entries - part * fragments_per_part_);
        fragment_parts_.push_back(make_buffer(GLsizeiptr(count * 4), nullptr, 0));
        GLuint t = 0;
        glCreateTextures(GL_TEXTURE_BUFFER, 1, &t);
        glTextureBuffer(t, GL_R32UI, fragment_parts_.back().get());
        fragment_textures_.emplace_back(t);
    }
}

void VoxelStructure::fill_lists(const VoxelRtPrograms& p, const ResidentSegments& s, float radius_mm) {
    glUseProgram(p.voxelize.get());
    bind_segments(p.voxelize, s, grid_, radius_mm);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kCells, cells_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kCursor, cursor_.get());
    for (unsigned part = 0; part < binding::kFragmentParts; ++part)
        glBindImageTexture(part, fragment_textures_[part < fragment_textures_.size() ? part : 0].get(), 0, GL_FALSE, 0,
                           GL_WRITE_ONLY, GL_R32UI);
    glProgramUniform1ui(p.voxelize.get(), uniform(p.voxelize, "uFragmentsPerPart"), fragments_per_part_);
    glProgramUniform1ui(p.voxelize.get(), uniform(p.voxelize, "uPass"), 1);
    dispatch_segments(p.voxelize, s);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void VoxelStructure::build_occupancy(const VoxelRtPrograms& p) {
    occupancy_ = make_volume(grid_.n, mip_levels(grid_.n));
    glUseProgram(p.occupancy.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kCells, cells_.get());
    glProgramUniform1ui(p.occupancy.get(), uniform(p.occupancy, "uGridN"), GLuint(grid_.n));
    glBindImageTexture(0, occupancy_.get(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R16F);
    const GLuint groups = GLuint((grid_.n + 3) / 4);
    glDispatchCompute(groups, groups, groups);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    // The averaging mip pyramid the cones sample.
    glGenerateTextureMipmap(occupancy_.get());
}

void VoxelStructure::build_occupied_pyramid(const VoxelRtPrograms& p) {
    pyramid_ = pyramid_layout(grid_.n);
    const std::vector<std::uint32_t>& offset = pyramid_.level_offset;
    const std::uint64_t stored = offset.size() > 1 ? pyramid_.cells - offset[1] : 1;
    occupied_ = make_buffer(GLsizeiptr(stored), nullptr, 0);
    GLuint t = 0;
    glCreateTextures(GL_TEXTURE_BUFFER, 1, &t);
    glTextureBuffer(t, GL_R8UI, occupied_.get());
    occupied_texture_ = GlTexture(t);
    const GLuint id = p.occupied_pyramid.get();
    glUseProgram(id);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kCells, cells_.get());
    glBindImageTexture(0, occupied_texture_.get(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_R8UI);
    glProgramUniform1ui(id, uniform(p.occupied_pyramid, "uGridN"), GLuint(grid_.n));
    for (std::size_t level = 1; level < offset.size(); ++level) {
        glProgramUniform1ui(id, uniform(p.occupied_pyramid, "uLevel"), GLuint(level));
        glProgramUniform1ui(id, uniform(p.occupied_pyramid, "uLevelOffset"), offset[level] - offset[1]);
        glProgramUniform1ui(id, uniform(p.occupied_pyramid, "uChildOffset"),
                            level > 1 ? offset[level - 1] - offset[1] : 0);
        const GLuint groups = GLuint(((grid_.n >> level) + 3) / 4);
        glDispatchCompute(groups, groups, groups);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
    }
}

void VoxelStructure::build_ambient_occlusion(const VoxelRtPrograms& p) {
    ambient_occlusion_ = make_volume(grid_.n, 1);
    glUseProgram(p.ambient_occlusion.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kCells, cells_.get());
    glProgramUniform1ui(p.ambient_occlusion.get(), uniform(p.ambient_occlusion, "uGridN"), GLuint(grid_.n));
    glBindTextureUnit(0, occupancy_.get());
    glBindImageTexture(0, ambient_occlusion_.get(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R16F);
    const GLuint groups = GLuint((grid_.n + 3) / 4);
    glDispatchCompute(groups, groups, groups);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
}

void VoxelStructure::bind(const GlProgram* trace) const {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kCells, cells_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kOffsets, offsets_.get());
    for (unsigned part = 0; part < binding::kFragmentParts; ++part)
        glBindTextureUnit(binding::kFragmentUnit + part,
                          fragment_textures_[part < fragment_textures_.size() ? part : 0].get());
    if (trace) glProgramUniform1ui(trace->get(), uniform(*trace, "uFragmentsPerPart"), fragments_per_part_);
    glBindTextureUnit(0, occupancy_.get());
    glBindTextureUnit(1, ambient_occlusion_ ? ambient_occlusion_.get() : occupancy_.get());
    glBindTextureUnit(binding::kOccupiedUnit, occupied_texture_.get());
    if (!trace) return;
    const GLuint id = trace->get();
    glProgramUniform1i(id, uniform(*trace, "uPyramidLevels"), GLint(pyramid_.level_offset.size()));
    glProgramUniform1uiv(id, uniform(*trace, "uPyramidOffset"), GLsizei(pyramid_.level_offset.size()),
                         pyramid_.level_offset.data());
}

std::vector<std::uint32_t> VoxelStructure::read_cells() const {
    std::vector<std::uint32_t> out(voxel_count(grid_));
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(cells_.get(), 0, GLsizeiptr(out.size() * 4), out.data());
    return out;
}

std::vector<std::uint8_t> VoxelStructure::read_occupied_pyramid() const {
    const std::vector<std::uint32_t>& offset = pyramid_.level_offset;
    std::vector<std::uint8_t> out(offset.size() > 1 ? pyramid_.cells - offset[1] : 0);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    if (!out.empty()) glGetNamedBufferSubData(occupied_.get(), 0, GLsizeiptr(out.size()), out.data());
    return out;
}

std::vector<float> VoxelStructure::read_ambient_occlusion() const {
    if (!ambient_occlusion_) return {};
    std::vector<float> out(voxel_count(grid_));
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
    glGetTextureImage(ambient_occlusion_.get(), 0, GL_RED, GL_FLOAT, GLsizei(out.size() * 4), out.data());
    return out;
}

}  // namespace fiblet::viewer::voxel_rt
