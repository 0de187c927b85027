#include "fiblet_viewer/headless_render.hpp"

#include <algorithm>
#include <chrono>

#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/view.hpp"
#include "gl/gpu_timer.hpp"
#include "gl/headless_context.hpp"
#include "gl/png_file.hpp"
#include "overlays/overlay_sources.hpp"
#include "render/render_bench.hpp"
#include "render/render_target.hpp"
#include "render/renderer.hpp"
#include "techniques/technique_registry.hpp"
#include "render/supersampling.hpp"
#include "scene/block_decoder.hpp"
#include "scene/gpu_programs.hpp"
#include "scene/gpu_scene.hpp"
#include "scene/scene_file.hpp"
#include "window/orbit_camera.hpp"

namespace fiblet::viewer {

namespace {

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The voxel ray tracer's one-off preprocessing, when it ran.
std::optional<VoxelRtPreprocessing> voxel_rt_preprocessing(const Renderer& renderer, const RenderOptions& options) {
    const voxel_rt::VoxelRayTracer* rt =
        ray_traced(options) ? renderer.voxel_ray_tracer_if_made() : nullptr;
    const voxel_rt::VoxelStructure* vs = rt ? rt->structure() : nullptr;
    if (!vs) return std::nullopt;
    const voxel_rt::BuildTimes& bt = vs->times();
    VoxelRtPreprocessing p;
    p.grid = vs->grid().n;
    p.decode_ms = rt->last_decode_ms();
    p.count_ms = bt.count_ms, p.scan_ms = bt.scan_ms, p.fill_ms = bt.fill_ms, p.occupancy_ms = bt.occupancy_ms;
    p.ambient_occlusion_ms = bt.ambient_occlusion_ms;
    p.total_ms = rt->last_decode_ms() + bt.total_ms();
    p.fragments = vs->fragment_count();
    return p;
}

}  // namespace

HeadlessRenderResult render_headless(const HeadlessRenderJob& job,
                                     const std::function<void(const HeadlessScene&, const RenderBench&)>& on_bench) {
    if (!job.camera_path.empty() && job.camera_path.size() != job.outputs.size())
        throw Error(Errc::invalid_argument, "a camera path needs one camera per output");
    RenderOptions options = job.render;
    const HeadlessContext context;
    const GpuPrograms programs;
    const auto opened = std::chrono::steady_clock::now();
    const FftFile file = open_scene_file(job.input);
    const FiberStreaming streaming(file, job.gpu_budget_bytes, !job.fiber_colors.point_values_path.empty());
    // Every fiber, or the overview of a streamed file: what cameras are fitted to.
    const GpuScene first =
        first_scene(file, programs, streaming, job.fiber_colors, job.fiber_radii_path, job.fiber_opacity_source);
    RenderTarget target(job.width, job.height);
    Renderer renderer(programs);
    renderer.set_overlays(make_overlays(job.overlays, options));
    const float aspect = float(job.width) / float(job.height);
    auto camera_for = [&](float zoom) {
        return camera_from_spec(job.camera, first, aspect, job.fov_y_deg, job.zoom * zoom);
    };
    HeadlessRenderResult result;
    result.scene = {context.description(), first.fiber_count(), first.block_count(), first.segment_count(),
                    file.header().fibers, file.header().blocks, streaming.budget_bytes(), streaming.streams(),
                    milliseconds_since(opened)};
    // A streamed file holds, for each camera, the fibers it sees (beside the overview).
    std::optional<GpuScene> part;
    HeldScene held;
    auto scene_seen_by = [&](const Camera& camera) -> const GpuScene& {
        if (!streaming.streams()) return first;
        const auto start = std::chrono::steady_clock::now();
        hold_view(part, first, file, programs, streaming, camera, renderer.reach_mm(first, options));
        held = {part->fiber_count(), part->block_count(), first.gpu_bytes() + part->gpu_bytes(), milliseconds_since(start)};
        return *part;
    };

    if (job.bench) {
        const GpuScene& scene = scene_seen_by(camera_for(1));
        RenderBench bench;
        bench.cases = run_render_bench(scene, renderer, target, camera_for, options, job.frames, job.bench_views);
        if (std::find(job.bench_views.begin(), job.bench_views.end(), "decode") != job.bench_views.end())
            bench.full_decode = FullDecodeTimes{time_full_decode(scene, programs, GpuDecoder::scan, job.frames),
                                                time_full_decode(scene, programs, GpuDecoder::sequential, job.frames)};
        if (options.transparent())
            bench.transparency = run_transparency_bench(scene, renderer, target, camera_for(1), options, job.frames);
        bench.timing = timing_method_name(default_timing_method());
        bench.decoder = options.decoder.value_or(default_decoder());
        bench.voxel_rt = voxel_rt_preprocessing(renderer, options);
        if (on_bench) on_bench(result.scene, bench);
    }
    if (job.outputs.empty()) return result;
    // One image; a turntable (frame i turned 360 i / n degrees about the
    // camera's up axis); or the cameras of a path file. Every camera is
    // made (and checked) before the first frame is written.
    std::vector<Camera> cameras;
    for (const std::string& spec : job.camera_path)
        cameras.push_back(camera_from_spec(spec, first, aspect, job.fov_y_deg, job.zoom));
    if (cameras.empty()) {
        const Camera start = camera_for(1.0f);
        for (std::size_t i = 0; i < job.outputs.size(); ++i)
            cameras.push_back(turned_about_up(start, 360.0f * float(i) / float(job.outputs.size()), first.bounds()));
    }
    if (job.time_stages) options.time_stages = true;
    for (std::size_t i = 0; i < job.outputs.size(); ++i) {
        held = {first.fiber_count(), first.block_count(), first.gpu_bytes(), 0};
        const GpuScene& scene = scene_seen_by(cameras[i]);
        const SupersampledFrame frame =
            render_supersampled(renderer, scene, cameras[i], options, job.width, job.height, job.supersample);
        if (i == 0) result.first_image = frame.stats, result.first_image_scene = held;
        write_png(job.outputs[i], frame.image, job.overwrite);
    }
    return result;
}

}  // namespace fiblet::viewer
