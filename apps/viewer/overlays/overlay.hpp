// Something drawn in the same frame as the fibers, after them, into the
// same colour, fiber (0: not a fiber) and depth buffers, so that both
// occlude each other: ODF glyphs, background image slices. Overlays live
// under overlays/, one module each with its shaders beside it.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "fiblet/view.hpp"
#include "fiblet_viewer/render_options.hpp"

namespace fiblet::viewer {

class Overlay {
public:
    virtual ~Overlay() = default;
    // Draws with the frame's framebuffer bound and depth testing on.
    virtual void draw(const Camera& camera, const RenderOptions& options) = 0;
    // An axis-aligned box (world mm: low and high corners) holding all it
    // draws, for the camera's clip planes; nothing: no constraint.
    virtual std::optional<std::array<Vec3f, 2>> bounds() const { return std::nullopt; }
};

// The camera with its near and far planes widened (never narrowed) so that
// the overlays' boxes lie between them: the planes come from the fibers'
// bounds, and an image or glyphs beyond them would be clipped. The camera
// itself when they already do (the near plane stays positive: at least
// 1e-4 of the far one). Renderer::render draws fibers and overlays with it.
Camera clip_planes_covering(const Camera& camera, const std::vector<std::shared_ptr<Overlay>>& overlays);

}  // namespace fiblet::viewer
