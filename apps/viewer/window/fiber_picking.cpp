#include "window/fiber_picking.hpp"

#include <algorithm>
#include <limits>
#include <vector>

#include "render/renderer.hpp"
#include "techniques/technique_registry.hpp"

namespace fiblet::viewer {

std::optional<PickedFiber> pick_fiber(const RenderTarget& target, const GpuScene& scene, int x, int y,
                                      int radius_px) {
    const int x0 = std::max(x - radius_px, 0), x1 = std::min(x + radius_px + 1, target.width());
    const int y0 = std::max(y - radius_px, 0), y1 = std::min(y + radius_px + 1, target.height());
    if (x0 >= x1 || y0 >= y1) return std::nullopt;
    const std::vector<std::uint32_t> ids = target.read_fibers(x0, y0, x1 - x0, y1 - y0);
    int best = std::numeric_limits<int>::max();
    std::optional<PickedFiber> out;
    for (int py = y0; py < y1; ++py)
        for (int px = x0; px < x1; ++px) {
            const std::uint32_t v = ids[std::size_t(py - y0) * std::size_t(x1 - x0) + std::size_t(px - x0)];
            const int d2 = (px - x) * (px - x) + (py - y) * (py - y);
            if (v == 0 || v - 1 >= scene.fiber_count() || d2 >= best || d2 > radius_px * radius_px) continue;
            best = d2;
            const std::uint64_t index = v - 1;
            out = PickedFiber{scene.file_fiber(index), scene.fiber_id(index), scene.fiber_points(index), scene.fiber_length_mm(index),
                              px, py};
        }
    return out;
}

std::optional<PickedFiber> pick_fiber_in_frame(Renderer& renderer, const GpuScene& scene, const Camera& camera,
                                               const RenderOptions& options, RenderTarget& target, int x, int y,
                                               int radius_px) {
    if (options.transparent() && !ray_traced(options)) {
        RenderOptions opaque = options;
        opaque.opacity = 1;
        opaque.fiber_opacity = false;
        opaque.clear = true;
        renderer.render(scene, camera, opaque, target);
    }
    return pick_fiber(target, scene, x, y, radius_px);
}

}  // namespace fiblet::viewer
