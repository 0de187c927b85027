#include "render_bench.hpp"

#include <algorithm>
#include <chrono>
#include <functional>

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
                                        const RenderOptions& base, int frames) {
    struct View {
        const char* name;
        float zoom;
    };
    // The whole scene; a close-up where most blocks are off-screen; far away,
    // where most blocks are under the level-of-detail size.
    const View views[] = {{"overview", 1.0f}, {"close-up", 3.0f}, {"far", 0.08f}};
    std::vector<BenchCase> out;
    for (const View& v : views)
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
    return out;
}

}  // namespace fiblet::viewer
