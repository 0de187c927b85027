#include "render/render_bench.hpp"

#include <algorithm>
#include <chrono>
#include <functional>

#include "gl/gpu_timer.hpp"

namespace fiblet::viewer {

namespace {
double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const std::size_t m = v.size() / 2;
    return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}
}  // namespace

std::vector<BenchCase> run_render_bench(const GpuScene& scene, Renderer& renderer, RenderTarget& target,
                                        const std::function<Camera(float zoom)>& camera_for,
                                        const RenderOptions& base, int frames, const std::vector<std::string>& views) {
    struct View {
        const char* name;
        float zoom;
    };
    // The whole scene; a close-up where about a third of the blocks are
    // off-screen; far away, the scene about 24 pixels tall, where most blocks
    // are under the level-of-detail size (a block's bounding sphere is about
    // 12 mm across in a 90 mm brain).
    const View all[] = {{kBenchViews[0], 1.0f}, {kBenchViews[1], 3.0f}, {kBenchViews[2], 24.0f / float(target.height())}};
    std::vector<BenchCase> out;
    for (const View& v : all) {
        if (std::find(views.begin(), views.end(), v.name) == views.end()) continue;
        for (bool selection : {true, false}) {
            RenderOptions o = base;
            o.frustum_culling = o.level_of_detail = selection;
            o.time_stages = true;
            const Camera camera = camera_for(v.zoom);
            std::vector<double> cull, decode, draw, wall;
            FrameStats last;
            for (int f = -1; f < frames; ++f) {
                const auto t0 = std::chrono::steady_clock::now();
                last = renderer.render(scene, camera, o, target);
                glFinish();
                const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
                if (f < 0) continue;  // warm-up: shader compilation, first-touch allocations
                cull.push_back(last.cull_ms), decode.push_back(last.decode_ms), draw.push_back(last.draw_ms);
                wall.push_back(ms);
            }
            BenchCase c{v.name, selection, last, median(wall)};
            c.median.cull_ms = median(cull), c.median.decode_ms = median(decode), c.median.draw_ms = median(draw);
            out.push_back(c);
        }
    }
    return out;
}

namespace {
// Median wall time (ms) of `frames` frames after a warm-up one, glFinish included.
double median_frame_ms(const GpuScene& scene, Renderer& renderer, RenderTarget& target, const Camera& camera,
                       const RenderOptions& o, int frames) {
    std::vector<double> wall;
    for (int f = -1; f < frames; ++f) {
        const auto t0 = std::chrono::steady_clock::now();
        renderer.render(scene, camera, o, target);
        glFinish();
        if (f >= 0) wall.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    return median(wall);
}
}  // namespace

TransparencyBench run_transparency_bench(const GpuScene& scene, Renderer& renderer, RenderTarget& target,
                                         const Camera& camera, const RenderOptions& transparent, int frames) {
    RenderOptions opaque = transparent;
    opaque.opacity = 1;
    opaque.fiber_opacity = false;
    TransparencyBench b;
    b.opaque_ms = median_frame_ms(scene, renderer, target, camera, opaque, frames);
    b.transparent_ms = median_frame_ms(scene, renderer, target, camera, transparent, frames);
    b.extra_bytes = renderer.transparency_bytes();
    return b;
}

double time_full_decode(const GpuScene& scene, const GpuPrograms& programs, GpuDecoder kind, int frames) {
    const BlockDecoder decoder(programs, scene.header().points_per_block);
    std::vector<double> ms;
    for (int f = -1; f < frames; ++f) {
        GpuTimer timer(default_timing_method());
        timer.begin(Stage::decode);
        for (std::uint32_t first = 0; first < scene.block_count(); first += decoder.capacity()) {
            decoder.decode(scene, kind, false, first, std::min(decoder.capacity(), scene.block_count() - first));
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        }
        timer.end();
        if (f >= 0) ms.push_back(timer.collect()[std::size_t(Stage::decode)]);
    }
    return median(ms);
}

}  // namespace fiblet::viewer
