// `fiblet render`: the renderer without a window (EGL; Mesa's llvmpipe where
// there is no GPU) drawing PNG files, and its frame-time benchmark
// (render/render_bench.hpp).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fiblet_viewer/gpu_decoder.hpp"
#include "fiblet_viewer/render_options.hpp"
#include "fiblet_viewer/scene_sources.hpp"

namespace fiblet::viewer {

// What render_headless draws, and where to.
struct HeadlessRenderJob {
    std::string input;  // a .fft, or a .tck, .trk or TRX file compressed on the fly (scene/scene_file.hpp)
    int width = 1920, height = 1080;
    RenderOptions render;
    FiberColorSource fiber_colors;     // render.fiber_colors turns them on
    std::string fiber_radii_path;      // scene/fiber_radii.hpp; render.fiber_radii turns them on
    std::string fiber_opacity_source;  // scene/fiber_opacity.hpp; render.fiber_opacity turns them on
    OverlaySources overlays;           // glyphs and slices over the fibers
    std::string camera = "oblique";    // as camera_from_spec (window/orbit_camera.hpp)
    // GPU memory the scene may take (scene/fiber_streaming.hpp); 0: a share
    // of what the driver reports. A file beyond it is held in part: the
    // fibers each output's camera sees, as many as fit.
    std::uint64_t gpu_budget_bytes = 0;
    float fov_y_deg = 35, zoom = 1;

    // The benchmark, run first: `frames` timed frames per case, the views
    // of `bench_views` (kBenchViews) with and without culling + LoD, and
    // "decode": every block by each decoder.
    bool bench = false;
    int frames = 5;
    std::vector<std::string> bench_views;

    // The PNG files, drawn after the benchmark: one image, or the frames of
    // a movie. Output i of n is seen by camera_path[i] when camera_path is
    // given (a --camera spec per output), else by `camera` turned 360 i / n
    // degrees about its up axis (a turntable).
    std::vector<std::string> outputs;
    std::vector<std::string> camera_path;
    int supersample = 1;       // render_supersampled's factor
    bool overwrite = false;    // replace existing outputs
    bool time_stages = false;  // the images' FrameStats carry stage times (RenderOptions::time_stages)
};

// The scene as loaded, and the context that drew it.
struct HeadlessScene {
    std::string device;  // "renderer, GL version" as the driver reports them
    std::uint64_t fibers = 0, blocks = 0, segments = 0;  // held on the GPU (at first)
    std::uint64_t file_fibers = 0, file_blocks = 0;
    std::uint64_t gpu_budget_bytes = 0;
    bool streamed = false;  // the file exceeds the budget: a part is held at a time
    double first_scene_ms = 0;  // from opening the file to the first scene on the GPU
};

// What the GPU held for an image (streamed files hold the fibers its camera sees).
struct HeldScene {
    std::uint64_t fibers = 0, blocks = 0, gpu_bytes = 0;
    double load_ms = 0;  // choosing and uploading them (0: the first scene served)
};

// One case of the benchmark (run_render_bench).
struct BenchCase {
    std::string view;   // "overview", "close-up", "far"
    bool selection;     // frustum culling + level of detail on
    FrameStats median;  // stage times: medians over the frames; counts of the last frame
    double frame_ms;    // median wall time of a whole frame, glFinish included
};

// A transparent frame against the opaque one (run_transparency_bench).
struct TransparencyBench {
    double opaque_ms = 0, transparent_ms = 0;
    std::uint64_t extra_bytes = 0;
};

// The full decodes' median times, when the benchmark ran them.
struct FullDecodeTimes {
    double scan_ms = 0, sequential_ms = 0;
};

// The voxel ray tracer's one-off preprocessing (the warm-up frame's;
// voxel_rt/voxel_structure.hpp's BuildTimes).
struct VoxelRtPreprocessing {
    int grid = 0;  // voxels per side
    double decode_ms = 0, count_ms = 0, scan_ms = 0, fill_ms = 0, occupancy_ms = 0, ambient_occlusion_ms = 0;
    double total_ms = 0;  // decoding and every build step
    std::uint64_t fragments = 0;
};

struct RenderBench {
    const char* timing = "";  // how stages are timed (timing_method_name of default_timing_method)
    GpuDecoder decoder = GpuDecoder::scan;  // the decoder of the timed frames
    std::vector<BenchCase> cases;
    std::optional<FullDecodeTimes> full_decode;      // bench_views holds "decode"
    std::optional<TransparencyBench> transparency;   // render.transparent()
    std::optional<VoxelRtPreprocessing> voxel_rt;    // render.engine voxel_rt, when it ran
};

struct HeadlessRenderResult {
    HeadlessScene scene;
    FrameStats first_image;  // the first output's frame (supersampled: the enlarged frame)
    HeldScene first_image_scene;
};

// Makes a headless OpenGL 4.5 context, opens the scene, runs the benchmark
// (job.bench) and hands it to `on_bench`, then draws and writes every
// output. Throws fiblet::Error: unsupported without a context, as
// open_scene_file, reading the per-fiber sources and the overlays, for a
// camera spec (invalid_argument), writing a PNG.
HeadlessRenderResult render_headless(
    const HeadlessRenderJob& job,
    const std::function<void(const HeadlessScene&, const RenderBench&)>& on_bench = {});

}  // namespace fiblet::viewer
