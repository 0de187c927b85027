// Picking: which fiber is drawn at a pixel, read from the render target's
// 32-bit fiber buffer (the fiber's index + 1, written by the same draw as the
// colour, so it follows the depth test).
#pragma once

#include <cstdint>
#include <optional>

#include "scene/gpu_scene.hpp"
#include "fiblet_viewer/render_options.hpp"
#include "render/render_target.hpp"

namespace fiblet::viewer {

struct PickedFiber {
    std::uint64_t index = 0;  // position of the fiber in the file
    std::uint32_t id = 0;     // fiber ID stored in its blocks
    std::uint32_t points = 0;
    double length_mm = 0;     // nominal: (points - 1) x step
    int x = 0, y = 0;         // the pixel it was found at
};

// The fiber at pixel (x, y) (from the top-left), or the nearest one within
// `radius_px` pixels, as drawn by the last frame into `target`.
std::optional<PickedFiber> pick_fiber(const RenderTarget& target, const GpuScene& scene, int x, int y,
                                      int radius_px = 3);

class Renderer;
// pick_fiber for a frame drawn with `options`: a transparent frame leaves no
// fiber indices (its fibers blend without depth), so the frame is drawn
// again opaque into `target` (opacity 1, no per-fiber opacity) and the
// fiber picked is the nearest one drawn there, whatever its opacity; the
// caller redraws the transparent frame. An opaque frame is read as drawn.
std::optional<PickedFiber> pick_fiber_in_frame(Renderer& renderer, const GpuScene& scene, const Camera& camera,
                                               const RenderOptions& options, RenderTarget& target, int x, int y,
                                               int radius_px = 3);

}  // namespace fiblet::viewer
