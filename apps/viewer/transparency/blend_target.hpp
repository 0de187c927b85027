// Where a transparent frame blends: a float (RGBA32F) image of the target's
// size, so that thousands of layers at a low opacity add up without the
// rounding of an 8-bit image at every blend (at opacity 0.05 an RGBA8 sum
// stops moving ten levels short of its value); resolved into the target
// once the frame is drawn.
#pragma once

#include <array>
#include <cstdint>

#include "gl/gl_objects.hpp"
#include "render/render_target.hpp"

namespace fiblet::viewer {

class BlendTarget {
public:
    // Binds the float image (the target's size) for drawing, filled with the
    // background (`clear`) or with the target's colours, and sets blending
    // with each fragment's alpha (its fiber's opacity, fiber_colors.glsl):
    // dst = alpha src + (1 - alpha) dst, in the order the fragments are
    // drawn; the image's alpha stays 1. No depth test.
    void begin(RenderTarget& target, bool clear, const std::array<float, 3>& background);
    // Writes the blended image into the target's colours (its fiber indices
    // are left as cleared) and restores opaque drawing.
    void resolve(RenderTarget& target);
    std::uint64_t gpu_bytes() const { return std::uint64_t(width_) * std::uint64_t(height_) * 16; }

private:
    void ensure_size(int width, int height);
    GlTexture color_;
    GlFramebuffer framebuffer_;
    int width_ = 0, height_ = 0;
};

}  // namespace fiblet::viewer
