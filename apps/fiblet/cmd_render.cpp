// fiblet render IN -o OUT.png — the viewer's renderer without a window
// (EGL; Mesa's llvmpipe where there is no GPU), and its frame-time benchmark.
#include <fmt/core.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <fstream>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "fiblet/error.hpp"
#include "fiblet_viewer/headless_render.hpp"
#include "viewer_options.hpp"

namespace fiblet::cli {
namespace {

struct RenderArgs {
    ViewerArgs view;
    std::string output;
    bool force = false, quiet = false, bench = false, json = false;
    int frames = 5;
    // Benchmark cases: views of kBenchViews, and "decode" (every block by each decoder).
    std::vector<std::string> bench_views{"overview", "close-up", "far", "decode"};
    int orbit = 0;  // turntable frames (0: one image)
    std::string camera_path;  // a file of --camera specs, one frame each
};

// The camera specs of a camera-path file: one per line, blank and '#' lines skipped.
std::vector<std::string> read_camera_path(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw Error(Errc::io, path + ": cannot be read");
    std::vector<std::string> specs;
    std::string line;
    while (std::getline(in, line)) {
        const std::size_t first = line.find_first_not_of(" \t\r"), last = line.find_last_not_of(" \t\r");
        if (first == std::string::npos || line[first] == '#') continue;
        specs.push_back(line.substr(first, last - first + 1));
    }
    if (specs.empty()) throw Error(Errc::invalid_argument, "--camera-path: " + path + " holds no camera");
    return specs;
}

// Frame i of n of "dir/name.png": "dir/name-007.png" (at least three digits).
std::string frame_path(const std::string& output, int i, int n) {
    const std::filesystem::path p(output);
    const int digits = std::max(3, int(std::to_string(std::max(n - 1, 0)).size()));
    std::filesystem::path name = p.stem();
    name += fmt::format("-{:0{}}", i, digits);
    name += p.extension();
    return (p.parent_path() / name).string();
}

std::string stats_json(const viewer::FrameStats& s) {
    return Json{}
        .integer("blocks_tested", s.tested_blocks)
        .integer("blocks_drawn", s.drawn_blocks())
        .integer("blocks_skipped", s.skipped_blocks())
        .integer("full_blocks", s.fine_blocks)
        .integer("coarse_blocks", s.coarse_blocks)
        .integer("segments", s.drawn_segments())
        .num("cull_ms", s.cull_ms)
        .num("decode_ms", s.decode_ms)
        .num("draw_ms", s.draw_ms)
        .render();
}

// The file, the budget and what the GPU held for the image.
std::string scene_json(const viewer::HeadlessScene& s, const viewer::HeldScene& held) {
    return Json{}
        .integer("file_fibers", s.file_fibers)
        .integer("file_blocks", s.file_blocks)
        .integer("gpu_budget_bytes", s.gpu_budget_bytes)
        .boolean("streamed", s.streamed)
        .num("first_scene_ms", s.first_scene_ms)
        .integer("fibers_held", held.fibers)
        .integer("blocks_held", held.blocks)
        .integer("gpu_bytes", held.gpu_bytes)
        .num("load_ms", held.load_ms)
        .render();
}

std::string transparency_json(const viewer::TransparencyBench& t, const viewer::RenderOptions& o) {
    return Json{}
        .str("mode", viewer::transparency_mode_name(o.transparency))
        .num("opacity", o.opacity)
        .num("opaque_frame_ms", t.opaque_ms)
        .num("frame_ms", t.transparent_ms)
        .integer("gpu_bytes", t.extra_bytes)
        .render();
}

void print_bench(const RenderArgs& a, const viewer::HeadlessScene& scene, int width, int height,
                 const viewer::RenderBench& bench, const viewer::RenderOptions& options) {
    const std::vector<viewer::BenchCase>& cases = bench.cases;
    const std::optional<viewer::FullDecodeTimes>& full = bench.full_decode;
    const std::optional<viewer::TransparencyBench>& transparency = bench.transparency;
    const viewer::GpuDecoder decoder = bench.decoder;
    const viewer::DrawStyle style = options.style;
    // The voxel ray tracer's one-off preprocessing (the warm-up frame's).
    const std::optional<viewer::VoxelRtPreprocessing>& vs = bench.voxel_rt;
    if (a.json) {
        std::string list = "[";
        for (std::size_t i = 0; i < cases.size(); ++i) {
            const auto& c = cases[i];
            list += (i ? ", " : "") + Json{}
                                          .str("view", c.view)
                                          .boolean("culling_and_lod", c.selection)
                                          .raw("gpu", stats_json(c.median))
                                          .num("frame_ms", c.frame_ms)
                                          .render();
        }
        fmt::print("{}\n", Json{}
                               .str("file", a.view.input)
                               .str("device", scene.device)
                               .str("timing", bench.timing)
                               .integer("width", std::uint64_t(width))
                               .integer("height", std::uint64_t(height))
                               .integer("frames", std::uint64_t(a.frames))
                               .integer("fibers", scene.fibers)
                               .integer("blocks", scene.blocks)
                               .str("decoder", viewer::gpu_decoder_name(decoder))
                               .str("style", viewer::draw_style_name(style))
                               .str("engine", a.view.engine)
                               .raw("voxel_rt", vs ? Json{}
                                                         .integer("grid", std::uint64_t(vs->grid))
                                                         .num("decode_ms", vs->decode_ms)
                                                         .num("count_ms", vs->count_ms)
                                                         .num("scan_ms", vs->scan_ms)
                                                         .num("fill_ms", vs->fill_ms)
                                                         .num("occupancy_ms", vs->occupancy_ms)
                                                         .num("ambient_occlusion_ms", vs->ambient_occlusion_ms)
                                                         .integer("fragments", vs->fragments)
                                                         .render()
                                                   : "null")
                               .num("radius_mm", a.view.radius)
                               .raw("decode_all_scan_ms", full ? fmt::format("{}", full->scan_ms) : "null")
                               .raw("decode_all_sequential_ms", full ? fmt::format("{}", full->sequential_ms) : "null")
                               .raw("cases", list + "]")
                               .raw("transparency", transparency ? transparency_json(*transparency, options) : "null")
                               .render());
        return;
    }
    fmt::print("{}: {} fibers, {} blocks, {} segments; {}x{}, median of {} frames\n", a.view.input,
               scene.fibers, scene.blocks, scene.segments, width, height, a.frames);
    fmt::print("device: {}; stage times by {}\n", scene.device, bench.timing);
    fmt::print("style: {}{}\n", viewer::draw_style_name(style),
               style == viewer::DrawStyle::tubes ? fmt::format(", radius {} mm", a.view.radius) : "");
    if (vs)
        fmt::print("engine: voxel-rt, {}³ grid, capsule radius {} mm{}{}{}: preprocessing once (first frame) {:.1f} ms: "
                   "decode {:.1f}, voxelize (counts + occupancy) {:.1f}, prefix sum {:.1f}, fragment lists {:.1f}, "
                   "occupancy pyramid {:.1f}, ambient occlusion {:.1f}; {} fragments ({:.1f} MiB)\n",
                   vs->grid, a.view.radius, a.view.ao ? ", --ao" : "", a.view.shadows ? ", --shadows" : "",
                   a.view.opacity < 1 ? fmt::format(", --opacity {}", a.view.opacity) : "",
                   vs->total_ms, vs->decode_ms, vs->count_ms, vs->scan_ms, vs->fill_ms,
                   vs->occupancy_ms, vs->ambient_occlusion_ms, vs->fragments,
                   double(vs->fragments) * 4 / (1 << 20));
    if (full)
        fmt::print("decoding all {} blocks: scan {:.2f} ms, sequential {:.2f} ms; frames below use the {} decoder\n",
                   scene.blocks, full->scan_ms, full->sequential_ms, viewer::gpu_decoder_name(decoder));
    fmt::print("{:<9} {:<12} {:>10} {:>10} {:>11} {:>9} {:>10} {:>9} {:>10} {:>9}\n", "view", "culling+LoD",
               "full blks", "coarse", "segments", "cull ms", "decode ms", "draw ms", "GPU ms", "frame ms");
    for (const auto& c : cases) {
        const auto& s = c.median;
        fmt::print("{:<9} {:<12} {:>10} {:>10} {:>11} {:>9.2f} {:>10.2f} {:>9.2f} {:>10.2f} {:>9.2f}\n", c.view,
                   c.selection ? "on" : "off", s.fine_blocks, s.coarse_blocks, s.drawn_segments(), s.cull_ms,
                   s.decode_ms, s.draw_ms, s.cull_ms + s.decode_ms + s.draw_ms, c.frame_ms);
    }
    if (transparency)
        fmt::print("transparency {} at opacity {}: overview frame {:.2f} ms vs opaque {:.2f} ms ({:.2f}x); {:.1f} MB "
                   "of GPU memory for it\n",
                   viewer::transparency_mode_name(options.transparency), options.opacity, transparency->transparent_ms,
                   transparency->opaque_ms,
                   transparency->opaque_ms > 0 ? transparency->transparent_ms / transparency->opaque_ms : 0.0,
                   double(transparency->extra_bytes) / 1e6);
    for (std::size_t i = 0; i + 1 < cases.size(); i += 2) {
        const auto gpu = [](const viewer::BenchCase& c) { return c.median.cull_ms + c.median.decode_ms + c.median.draw_ms; };
        fmt::print("{}: culling+LoD makes the GPU frame {:.2f}x faster ({:.2f} -> {:.2f} ms)\n", cases[i].view,
                   gpu(cases[i]) > 0 ? gpu(cases[i + 1]) / gpu(cases[i]) : 0.0, gpu(cases[i + 1]), gpu(cases[i]));
    }
}

void run(const RenderArgs& a) {
    int width = 0, height = 0;
    parse_size(a.view.size, width, height);
    viewer::RenderOptions options = render_options_from(a.view);
    const viewer::OverlaySources overlay_sources = overlay_sources_from(a.view);
    if (!a.bench && a.output.empty()) throw Error(Errc::invalid_argument, "-o OUT.png is required (or --bench)");
    if (a.orbit < 0 || a.orbit > 100000) throw Error(Errc::invalid_argument, "--orbit must be in 0..100000 frames");
    if ((a.orbit > 0 || !a.camera_path.empty()) && a.output.empty())
        throw Error(Errc::invalid_argument, "--orbit and --camera-path need -o OUT.png");
    if (a.orbit > 0 && !a.camera_path.empty())
        throw Error(Errc::invalid_argument, "--orbit and --camera-path exclude each other");
    const std::vector<std::string> path_specs = a.camera_path.empty() ? std::vector<std::string>{} : read_camera_path(a.camera_path);
    const int movie = a.orbit > 0 ? a.orbit : int(path_specs.size());  // frames of a movie, 0: one image
    std::vector<std::string> outputs;
    if (!a.output.empty())
        for (int i = 0; i < std::max(movie, 1); ++i) outputs.push_back(movie ? frame_path(a.output, i, movie) : a.output);
    for (const std::string& out : outputs)
        if (!a.force && std::filesystem::exists(out)) throw Error(Errc::exists, out + ": output exists", Remedy::overwrite);
    if (a.frames < 1) throw Error(Errc::invalid_argument, "--frames must be at least 1");

    viewer::HeadlessRenderJob job;
    job.input = a.view.input, job.width = width, job.height = height;
    job.render = options;
    job.fiber_colors = fiber_color_source(a.view);
    job.fiber_radii_path = a.view.fiber_radii, job.fiber_opacity_source = a.view.fiber_opacity;
    job.overlays = overlay_sources;
    job.camera = a.view.camera, job.fov_y_deg = a.view.fov, job.zoom = a.view.zoom;
    job.gpu_budget_bytes = gpu_budget_bytes(a.view);
    job.bench = a.bench, job.frames = a.frames, job.bench_views = a.bench_views;
    job.outputs = outputs, job.camera_path = path_specs;
    job.supersample = a.view.supersample, job.overwrite = a.force;
    // --json reports the frame's stage times (cull, decode, draw; voxel-rt:
    // preprocessing and trace), so that one frame of a big file is measured
    // without the benchmark's many.
    job.time_stages = a.json;
    const viewer::HeadlessRenderResult result =
        viewer::render_headless(job, [&](const viewer::HeadlessScene& scene, const viewer::RenderBench& bench) {
            print_bench(a, scene, width, height, bench, options);
        });
    if (a.output.empty()) return;
    const viewer::HeadlessScene& scene = result.scene;
    const viewer::FrameStats& stats = result.first_image;
    if (movie > 0) {
        if (!a.quiet)
            fmt::print("{} -> {} .. {} ({} frames, {}x{})\n", a.view.input, outputs.front(), outputs.back(),
                       outputs.size(), width, height);
        return;
    }
    if (a.json && !a.bench) {
        fmt::print("{}\n", Json{}
                               .str("input", a.view.input)
                               .str("output", a.output)
                               .str("device", scene.device)
                               .raw("scene", scene_json(scene, result.first_image_scene))
                               .raw("frame", stats_json(stats))
                               .render());
    } else if (!a.quiet && !a.bench) {
        fmt::print("{} -> {} ({}x{})\n", a.view.input, a.output, width, height);
        fmt::print("  drew {} of {} blocks ({} full, {} as one segment), {} segments; {} tested, {} skipped\n",
                   stats.drawn_blocks(), scene.blocks, stats.fine_blocks, stats.coarse_blocks, stats.drawn_segments(),
                   stats.tested_blocks, stats.skipped_blocks());
    }
}

}  // namespace

void add_render(CLI::App& app) {
    auto args = std::make_shared<RenderArgs>();
    CLI::App* cmd = app.add_subcommand("render", "Render a .fft (or .tck, .trk, TRX) file to a PNG without a window (EGL)");
    add_viewer_options(cmd, args->view);
    cmd->add_option("-o,--output", args->output, "Output PNG");
    cmd->add_option("--size", args->view.size, "Image size WIDTHxHEIGHT")->capture_default_str();
    cmd->add_flag("-f,--force", args->force, "Overwrite the output");
    cmd->add_flag("-q,--quiet", args->quiet, "Print nothing on success");
    cmd->add_flag("--json", args->json, "Print the frame statistics (or the benchmark) as JSON");
    cmd->add_flag("--bench", args->bench,
                  "Time frames (cull / decode / draw: GL timer queries, glFinish on software renderers) "
                  "from three distances, with and without culling + LoD");
    cmd->add_option("--frames", args->frames, "Timed frames per benchmark case")->capture_default_str();
    cmd->add_option("--bench-views", args->bench_views,
                    "Benchmark cases, comma-separated: overview, close-up, far (each with and without culling + "
                    "LoD), decode (every block by each GPU decoder)")
        ->delimiter(',')
        ->check(CLI::IsMember({"overview", "close-up", "far", "decode"}))
        ->capture_default_str();
    cmd->add_option("--orbit", args->orbit,
                    "Write N frames turning once around the target about the camera's up axis, OUT-000.png "
                    "... (a turntable movie)");
    cmd->add_option("--camera-path", args->camera_path,
                    "A file of cameras, one --camera spec a line ('#' lines skipped): one frame each, "
                    "OUT-000.png ...")
        ->check(CLI::ExistingFile);
    cmd->callback([args] { run(*args); });
}

}  // namespace fiblet::cli
