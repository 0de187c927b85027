#include "render/renderer.hpp"

#include <algorithm>
#include <cmath>

#include "gl/gpu_timer.hpp"
#include "gl/shader_program.hpp"
#include "render/shading_uniforms.hpp"
#include "render/vec_ops.hpp"
#include "techniques/tubes/tube_spline.hpp"

namespace fiblet::viewer {

namespace {

// Points of a fiber of `mm` length at the file's step: length = (points - 1) step.
std::uint32_t points_for_length(double mm, double step_mm, bool round_up) {
    if (!std::isfinite(mm)) return 0xffffffffu;
    const double p = mm / step_mm + 1.0;
    const double r = round_up ? std::ceil(p - 1e-9) : std::floor(p + 1e-9);
    return std::uint32_t(std::clamp(r, 0.0, 4294967295.0));
}

}  // namespace

Renderer::Renderer(const GpuPrograms& programs) : programs_(programs), techniques_(programs) {
    GLuint vao = 0;
    glCreateVertexArrays(1, &vao);
    empty_vertex_array_ = GlVertexArray(vao);
    counters_ = make_buffer(sizeof(DrawCounters), nullptr, GL_DYNAMIC_STORAGE_BIT);
}

void Renderer::ensure_buffers(const GpuScene& scene, bool decisions) {
    const std::uint32_t blocks = std::max(scene.block_count(), 1u);
    if (list_capacity_ < blocks) {
        fine_list_ = make_buffer(GLsizeiptr(blocks) * 4, nullptr, 0);
        coarse_list_ = make_buffer(GLsizeiptr(blocks) * 4, nullptr, 0);
        list_capacity_ = blocks;
    }
    if (decisions && decisions_capacity_ < blocks) {
        decisions_ = make_buffer(GLsizeiptr(blocks) * 4, nullptr, 0);
        decisions_capacity_ = blocks;
    }
    if (!decoder_ || decoder_->points_per_block() != scene.header().points_per_block)
        decoder_ = std::make_unique<BlockDecoder>(programs_, scene.header().points_per_block);
}

DrawCounters Renderer::select_blocks(const GpuScene& scene, const Camera& camera, const Viewport& viewport,
                                     const RenderOptions& o) {
    ensure_buffers(scene, o.record_decisions);
    const GlProgram& p = programs_.cull;
    const GLuint id = p.get();
    glUseProgram(id);
    scene.bind(p);
    const GLuint zero = 0;
    glClearNamedBufferData(counters_.get(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kFineList, fine_list_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kCoarseList, coarse_list_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kCounters, counters_.get());
    const bool decisions = o.record_decisions && decisions_;
    if (decisions) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kDecisions, decisions_.get());
    glProgramUniform1i(id, uniform(p, "uWriteDecisions"), decisions ? 1 : 0);

    // The frustum planes and LoD terms of view.hpp, computed on the CPU once.
    const Frustum f = frustum_from_camera(camera);
    float planes[24];
    for (int i = 0; i < 6; ++i) {
        const Plane& pl = f.planes[std::size_t(i)];
        planes[4 * i] = pl.n.x, planes[4 * i + 1] = pl.n.y, planes[4 * i + 2] = pl.n.z, planes[4 * i + 3] = pl.d;
    }
    glProgramUniform1i(id, uniform(p, "uFrustumCulling"), o.frustum_culling ? 1 : 0);
    glProgramUniform4fv(id, uniform(p, "uPlanes"), 6, planes);
    // Spheres grow by what the style draws beyond the centre lines (a tube's radius).
    glProgramUniform1f(id, uniform(p, "uSphereMargin"), reach_mm(scene, o));
    const CameraBasis basis = camera_basis(camera);
    glProgramUniform1i(id, uniform(p, "uLevelOfDetail"), o.level_of_detail ? 1 : 0);
    glProgramUniform1f(id, uniform(p, "uLodPixels"), o.lod_pixels);
    glProgramUniform3f(id, uniform(p, "uCameraPosition"), camera.position.x, camera.position.y, camera.position.z);
    glProgramUniform3f(id, uniform(p, "uCameraBack"), basis.back.x, basis.back.y, basis.back.z);
    glProgramUniform1f(id, uniform(p, "uTanHalfFovY"), std::tan(camera.fov_y_deg * float(M_PI) / 360.0f));
    glProgramUniform1f(id, uniform(p, "uViewportHeight"), float(viewport.height));

    const double step_mm = double(scene.header().step) * scene.header().scaling;
    glProgramUniform2ui(id, uniform(p, "uFiberIdRange"), o.id_min, o.id_max);
    glProgramUniform2ui(id, uniform(p, "uPointRange"), points_for_length(o.min_length_mm, step_mm, true),
                        points_for_length(o.max_length_mm, step_mm, false));

    glDispatchCompute((scene.block_count() + 63) / 64, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    DrawCounters c;
    glGetNamedBufferSubData(counters_.get(), 0, sizeof c, &c);
    return c;
}

float Renderer::reach_mm(const GpuScene& scene, const RenderOptions& o) {
    return ray_traced(o) ? tube_radius_reach(scene, o) : techniques_.style(o.style).reach_mm(scene, o);
}

voxel_rt::VoxelRayTracer& Renderer::voxel_ray_tracer() {
    if (!voxel_ray_tracer_) voxel_ray_tracer_ = std::make_unique<voxel_rt::VoxelRayTracer>(programs_);
    return *voxel_ray_tracer_;
}

FrameStats Renderer::render(const GpuScene& scene, const Camera& requested, const RenderOptions& file_options,
                            RenderTarget& target) {
    // Highlighted fibers are the file's; the shaders see the scene's.
    RenderOptions options = file_options;
    if (!scene.holds_every_fiber()) options.highlighted_fibers = scene.scene_fibers(file_options.highlighted_fibers);
    if (ray_traced(options)) return voxel_ray_tracer().render(scene, requested, options, target);
    // Near and far planes widened to hold the overlays (overlay.hpp).
    const Camera camera = clip_planes_covering(requested, overlays_);
    RenderOptions o = options;
    o.fiber_opacity = options.fiber_opacity && scene.has_fiber_opacities();
    // A transparent frame blends every segment of what it selects: no coarse blocks.
    if (o.transparent()) o.level_of_detail = false;
    o.fiber_colors = options.fiber_colors && scene.has_fiber_colors();
    o.point_values = options.point_values && scene.has_point_values();
    if (o.point_values && !o.value_range) o.value_range = scene.point_value_range();
    o.fiber_radii = options.fiber_radii && scene.has_fiber_radii();
    ensure_buffers(scene, o.record_decisions);
    // --ao: occlusion from one chord per block, built once per scene and grid.
    OcclusionVolume occlusion;
    if (o.ambient_occlusion) occlusion = voxel_ray_tracer().chord_occlusion(scene, o);
    const Viewport viewport{target.width(), target.height()};
    target.begin_frame(o.clear, o.background);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glBindVertexArray(empty_vertex_array_.get());

    GpuTimer timer(o.time_stages ? default_timing_method() : TimingMethod::none);
    const GpuDecoder decoder = o.decoder.value_or(default_decoder());
    FrameStats stats;
    const bool select = o.frustum_culling || o.level_of_detail || o.subset_active();
    if (select) {
        timer.begin(Stage::cull);
        const DrawCounters c = select_blocks(scene, camera, viewport, o);
        timer.end();
        stats.tested_blocks = scene.block_count();
        stats.fine_blocks = c.fine_blocks, stats.coarse_blocks = c.coarse_blocks;
        stats.fine_segments = c.fine_segments, stats.coarse_segments = c.coarse_segments;
    } else {
        stats.fine_blocks = scene.block_count();
        stats.fine_segments = scene.segment_count();
    }

    const FrameInputs in{scene, camera, o, select, o.ambient_occlusion ? &occlusion : nullptr};
    if (o.transparent()) blend_target_.begin(target, o.clear, o.background);
    const FramePlan plan = techniques_.plan(o);
    plan.order.draw(in, {*decoder_, decoder, fine_list_.get(), std::uint32_t(stats.fine_blocks), timer},
                    plan.technique);

    // Coarse blocks: one segment each, straight from the raw blocks.
    if (stats.coarse_blocks > 0) {
        timer.begin(Stage::draw);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kCoarseList, coarse_list_.get());
        techniques_.style(o.style).draw_coarse(in, std::uint32_t(stats.coarse_blocks));
        timer.end();
    }

    if (o.transparent()) blend_target_.resolve(target);

    // Overlays share the depth buffer: glyphs, slices and opaque fibers
    // occlude each other (transparent fibers leave no depth: drawn under them).
    if (!overlays_.empty()) {
        timer.begin(Stage::draw);
        for (const auto& overlay : overlays_) overlay->draw(camera, o);
        glBindVertexArray(empty_vertex_array_.get());
        timer.end();
    }

    // The colour bar of the per-point values, over everything.
    if (o.point_values && o.color_bar) {
        if (!color_bar_) color_bar_ = std::make_unique<ColorBar>();
        glDisable(GL_DEPTH_TEST);
        color_bar_->draw(target.width(), target.height(), o);
        glEnable(GL_DEPTH_TEST);
        glBindVertexArray(empty_vertex_array_.get());
    }

    const auto ms = timer.collect();
    stats.cull_ms = ms[0], stats.decode_ms = ms[1], stats.draw_ms = ms[2];
    return stats;
}

std::uint64_t Renderer::transparency_bytes() const {
    return blend_target_.gpu_bytes() + techniques_.order_bytes();
}

std::vector<BlockDecision> Renderer::read_decisions(const GpuScene& scene) const {
    std::vector<BlockDecision> out(scene.block_count());
    if (!decisions_ || out.empty()) return out;
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(decisions_.get(), 0, GLsizeiptr(out.size() * 4), out.data());
    return out;
}

}  // namespace fiblet::viewer
