#include "voxel_rt/voxel_ray_tracer.hpp"

#include <chrono>
#include <cmath>

#include "gl/shader_program.hpp"
#include "render/shading_uniforms.hpp"
#include "voxel_rt/voxel_rt_bindings.hpp"

namespace fiblet::viewer::voxel_rt {

VoxelRayTracer::VoxelRayTracer(const GpuPrograms& programs) : shared_(programs) {
    GLuint vao = 0;
    glCreateVertexArrays(1, &vao);
    empty_vertex_array_ = GlVertexArray(vao);
}

VoxelRayTracer::~VoxelRayTracer() = default;

void VoxelRayTracer::ensure_structure(const GpuScene& scene, const RenderOptions& o) {
    if (built_generation_ != scene.generation() || !segments_) {
        structure_.reset();
        segments_ = std::make_unique<SceneSegments>(scene, shared_, part_bytes_);
        built_scene_ = &scene, built_generation_ = scene.generation();
    }
    const bool ao = o.ambient_occlusion;
    const bool fiber_radii = o.fiber_radii && scene.has_fiber_radii();
    if (structure_ && built_grid_ == o.voxel_grid && built_radius_ == o.tube_radius_mm &&
        built_fiber_radii_ == fiber_radii && (!ao || structure_->has_ambient_occlusion()))
        return;
    culling_.reset();
    structure_.reset();  // its memory first
    // The grid's margin: the largest capsule radius.
    const VoxelGrid grid =
        grid_around(scene.bounds(), o.voxel_grid, fiber_radii ? scene.max_fiber_radius() : o.tube_radius_mm);
    structure_ = std::make_unique<VoxelStructure>(programs_, grid, segments_for(scene, o), o.tube_radius_mm, ao,
                                                  part_bytes_);
    built_grid_ = o.voxel_grid, built_radius_ = o.tube_radius_mm, built_fiber_radii_ = fiber_radii;
}

ResidentSegments VoxelRayTracer::segments_for(const GpuScene& scene, const RenderOptions& o) const {
    ResidentSegments s = segments_->segments();
    s.fiber_radii = o.fiber_radii && scene.has_fiber_radii();
    return s;
}

OcclusionVolume VoxelRayTracer::chord_occlusion(const GpuScene& scene, const RenderOptions& o) {
    if (!chords_ || chords_scene_ != scene.generation() || chords_grid_ != o.voxel_grid || chords_radius_ != o.tube_radius_mm) {
        chords_.reset();
        chords_ = std::make_unique<ChordOcclusion>(
            programs_, scene, grid_around(scene.bounds(), o.voxel_grid, o.tube_radius_mm), o.tube_radius_mm);
        chords_scene_ = scene.generation(), chords_grid_ = o.voxel_grid, chords_radius_ = o.tube_radius_mm;
    }
    return chords_->volume();
}

void VoxelRayTracer::trace(const Camera& camera, const RenderOptions& o, RenderTarget& target) {
    const GlProgram& p = programs_.trace;
    const GLuint id = p.get();
    glUseProgram(id);
    set_shading_uniforms(p, camera, o);
    bind_segments(p, segments_for(*built_scene_, o), structure_->grid(), o.tube_radius_mm);
    // Culling: opaque frames (nothing hides what lies behind a transparent
    // surface); --no-culling turns it off as it does the raster selection.
    const bool transparent = o.transparent();
    const bool cull = o.frustum_culling && !transparent;
    if (cull) {
        if (!culling_) culling_ = std::make_unique<VoxelCulling>(programs_, *structure_);
        culling_->update(programs_, *structure_, camera);
        glUseProgram(id);
        culling_->bind(p);
    } else {
        glProgramUniform1i(id, uniform(p, "uCulling"), 0);
        // A binding must hold a buffer: the cells stand in for the pyramid.
    }
    structure_->bind(&p);
    if (!cull) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kVisible, structure_->cells_buffer());
    const CameraBasis b = camera_basis(camera);
    glProgramUniform3f(id, uniform(p, "uCameraRight"), b.right.x, b.right.y, b.right.z);
    glProgramUniform3f(id, uniform(p, "uCameraUp"), b.up.x, b.up.y, b.up.z);
    glProgramUniform3f(id, uniform(p, "uCameraForward"), -b.back.x, -b.back.y, -b.back.z);
    glProgramUniform1f(id, uniform(p, "uTanHalfFovY"), std::tan(camera.fov_y_deg * float(M_PI) / 360.0f));
    glProgramUniform1f(id, uniform(p, "uAspect"), camera.aspect);
    glProgramUniform2f(id, uniform(p, "uViewportSize"), float(target.width()), float(target.height()));
    glProgramUniform1i(id, uniform(p, "uUseAmbientOcclusion"), o.ambient_occlusion ? 1 : 0);
    glProgramUniform1i(id, uniform(p, "uUseShadows"), o.shadows ? 1 : 0);
    glProgramUniform1i(id, uniform(p, "uWriteSegments"), write_segment_ids_ ? 1 : 0);
    glProgramUniform1i(id, uniform(p, "uTransparent"), transparent ? 1 : 0);
    glProgramUniform1i(id, uniform(p, "uEmptySpaceSkipping"), o.empty_space_skipping ? 1 : 0);
    if (transparent) {
        // Premultiplied colour over the background; the fiber buffer is an
        // integer attachment, which blending leaves alone.
        glEnablei(GL_BLEND, 0);
        glBlendFunci(0, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    }
    glBindVertexArray(empty_vertex_array_.get());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    if (transparent) glDisablei(GL_BLEND, 0);
}

FrameStats VoxelRayTracer::render(const GpuScene& scene, const Camera& camera, const RenderOptions& options,
                                  RenderTarget& target) {
    RenderOptions o = options;
    o.fiber_opacity = options.fiber_opacity && scene.has_fiber_opacities();
    target.begin_frame(false, o.background);  // the structure's passes may draw to it
    FrameStats stats;
    const auto t0 = std::chrono::steady_clock::now();
    const void* before = structure_.get();
    ensure_structure(scene, o);
    if (structure_.get() != before) {
        glFinish();
        stats.decode_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    }
    target.begin_frame(o.clear, o.background);
    // The trace writes the depth of its nearest hit: test it like the
    // rasterized styles, so that it composes with what the target holds.
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    if (o.time_stages) glFinish();
    const auto t1 = std::chrono::steady_clock::now();
    trace(camera, o, target);
    if (o.time_stages) {
        glFinish();
        stats.draw_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
    }
    stats.fine_blocks = scene.block_count();
    stats.fine_segments = scene.segment_count();
    return stats;
}

}  // namespace fiblet::viewer::voxel_rt
