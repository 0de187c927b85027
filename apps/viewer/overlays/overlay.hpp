// Something drawn in the same frame as the fibers, after them, into the
// same colour, fiber (0: not a fiber) and depth buffers, so that both
// occlude each other: ODF glyphs, background image slices. Overlays live
// under overlays/, one module each with its shaders beside it.
#pragma once

#include "fiblet/view.hpp"
#include "render_options.hpp"

namespace fiblet::viewer {

class Overlay {
public:
    virtual ~Overlay() = default;
    // Draws with the frame's framebuffer bound and depth testing on.
    virtual void draw(const Camera& camera, const RenderOptions& options) = 0;
};

}  // namespace fiblet::viewer
