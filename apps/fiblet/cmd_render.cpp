// fiblet render IN -o OUT.png — the viewer's renderer without a window
// (EGL; Mesa's llvmpipe where there is no GPU), and its frame-time benchmark.
#include <fmt/core.h>

#include <filesystem>

#include "cli_common.hpp"
#include "fiblet/error.hpp"
#include "gpu_programs.hpp"
#include "gpu_scene.hpp"
#include "gpu_timer.hpp"
#include "headless_context.hpp"
#include "orbit_camera.hpp"
#include "png_file.hpp"
#include "render_bench.hpp"
#include "render_target.hpp"
#include "renderer.hpp"
#include "scene_file.hpp"
#include "viewer_options.hpp"

namespace fiblet::cli {
namespace {

struct RenderArgs {
    ViewerArgs view;
    std::string output;
    bool force = false, quiet = false, bench = false, json = false;
    int frames = 5;
};

std::string stats_json(const viewer::FrameStats& s) {
    return Json{}
        .integer("full_blocks", s.fine_blocks)
        .integer("coarse_blocks", s.coarse_blocks)
        .integer("segments", s.drawn_segments())
        .num("cull_ms", s.cull_ms)
        .num("decode_ms", s.decode_ms)
        .num("draw_ms", s.draw_ms)
        .render();
}

void print_bench(const RenderArgs& a, const viewer::GpuScene& scene, const std::string& device, int width, int height,
                 const std::vector<viewer::BenchCase>& cases, double scan_ms, double sequential_ms,
                 viewer::DecoderKind decoder) {
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
                               .str("device", device)
                               .str("timing", viewer::timing_method_name(viewer::default_timing_method()))
                               .integer("width", std::uint64_t(width))
                               .integer("height", std::uint64_t(height))
                               .integer("frames", std::uint64_t(a.frames))
                               .integer("fibers", scene.fiber_count())
                               .integer("blocks", scene.block_count())
                               .str("decoder", viewer::decoder_name(decoder))
                               .num("decode_all_scan_ms", scan_ms)
                               .num("decode_all_sequential_ms", sequential_ms)
                               .raw("cases", list + "]")
                               .render());
        return;
    }
    fmt::print("{}: {} fibers, {} blocks, {} segments; {}x{}, median of {} frames\n", a.view.input,
               scene.fiber_count(), scene.block_count(), scene.segment_count(), width, height, a.frames);
    fmt::print("device: {}; stage times by {}\n", device, viewer::timing_method_name(viewer::default_timing_method()));
    fmt::print("decoding all {} blocks: scan {:.2f} ms, sequential {:.2f} ms; frames below use the {} decoder\n",
               scene.block_count(), scan_ms, sequential_ms, viewer::decoder_name(decoder));
    fmt::print("{:<9} {:<12} {:>10} {:>10} {:>11} {:>9} {:>10} {:>9} {:>10} {:>9}\n", "view", "culling+LoD",
               "full blks", "coarse", "segments", "cull ms", "decode ms", "draw ms", "GPU ms", "frame ms");
    for (const auto& c : cases) {
        const auto& s = c.median;
        fmt::print("{:<9} {:<12} {:>10} {:>10} {:>11} {:>9.2f} {:>10.2f} {:>9.2f} {:>10.2f} {:>9.2f}\n", c.view,
                   c.selection ? "on" : "off", s.fine_blocks, s.coarse_blocks, s.drawn_segments(), s.cull_ms,
                   s.decode_ms, s.draw_ms, s.cull_ms + s.decode_ms + s.draw_ms, c.frame_ms);
    }
    for (std::size_t i = 0; i + 1 < cases.size(); i += 2) {
        const auto gpu = [](const viewer::BenchCase& c) { return c.median.cull_ms + c.median.decode_ms + c.median.draw_ms; };
        fmt::print("{}: culling+LoD makes the GPU frame {:.2f}x faster ({:.2f} -> {:.2f} ms)\n", cases[i].view,
                   gpu(cases[i]) > 0 ? gpu(cases[i + 1]) / gpu(cases[i]) : 0.0, gpu(cases[i + 1]), gpu(cases[i]));
    }
}

void run(const RenderArgs& a) {
    int width = 0, height = 0;
    parse_size(a.view.size, width, height);
    const viewer::RenderOptions options = render_options_from(a.view);
    if (!a.bench && a.output.empty()) throw Error(Errc::invalid_argument, "-o OUT.png is required (or --bench)");
    if (!a.output.empty() && !a.force && std::filesystem::exists(a.output))
        throw Error(Errc::exists, a.output + " exists (use --force to overwrite)");
    if (a.frames < 1) throw Error(Errc::invalid_argument, "--frames must be at least 1");

    const viewer::HeadlessContext context;
    const viewer::GpuPrograms programs;
    const FftFile file = viewer::open_scene_file(a.view.input);
    const viewer::GpuScene scene(file, programs);
    viewer::RenderTarget target(width, height);
    viewer::Renderer renderer(programs);
    const float aspect = float(width) / float(height);
    auto camera_for = [&](float zoom) {
        return viewer::camera_from_spec(a.view.camera, scene, aspect, a.view.fov, a.view.zoom * zoom);
    };

    if (a.bench) {
        const auto cases = viewer::run_render_bench(scene, renderer, target, camera_for, options, a.frames);
        const double scan_ms = viewer::time_full_decode(scene, programs, viewer::DecoderKind::scan, a.frames);
        const double sequential_ms = viewer::time_full_decode(scene, programs, viewer::DecoderKind::sequential, a.frames);
        print_bench(a, scene, context.description(), width, height, cases, scan_ms, sequential_ms,
                    options.decoder.value_or(viewer::default_decoder()));
    }
    if (a.output.empty()) return;
    const viewer::FrameStats stats = renderer.render(scene, camera_for(1.0f), options, target);
    viewer::write_png(a.output, {width, height, target.read_rgba()}, a.force);
    if (a.json && !a.bench) {
        fmt::print("{}\n", Json{}
                               .str("input", a.view.input)
                               .str("output", a.output)
                               .str("device", context.description())
                               .raw("frame", stats_json(stats))
                               .render());
    } else if (!a.quiet && !a.bench) {
        fmt::print("{} -> {} ({}x{})\n", a.view.input, a.output, width, height);
        fmt::print("  drew {} of {} blocks ({} full, {} as one segment), {} segments\n", stats.drawn_blocks(),
                   scene.block_count(), stats.fine_blocks, stats.coarse_blocks, stats.drawn_segments());
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
    cmd->callback([args] { run(*args); });
}

}  // namespace fiblet::cli
