// The framebuffer a frame is drawn into: RGBA8 colour, a 32-bit fiber buffer
// for picking (fiber index + 1, 0 = background) and a depth buffer. The
// window shows it by a blit; headless rendering reads it back.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "gl/gl_objects.hpp"

namespace fiblet::viewer {

class RenderTarget {
public:
    RenderTarget(int width, int height);
    void resize(int width, int height);  // no-op when unchanged
    int width() const { return width_; }
    int height() const { return height_; }
    GLuint framebuffer() const { return framebuffer_.get(); }
    // Binds it for drawing over its whole size; with `clear`, fills it with
    // the background, no fiber and the far depth first.
    void begin_frame(bool clear, const std::array<float, 3>& background) const;

    // Colour as RGBA8, rows from the top of the image.
    std::vector<std::uint8_t> read_rgba() const;
    // Fiber buffer values (index + 1, 0 = none) of the rectangle at (x, y)
    // from the top-left, which must lie inside the target; rows from the top.
    std::vector<std::uint32_t> read_fibers(int x, int y, int width, int height) const;
    std::vector<std::uint32_t> read_fibers() const { return read_fibers(0, 0, width_, height_); }
    // Window depth (0 near .. 1 far) of every pixel, rows from the top.
    std::vector<float> read_depth() const;

private:
    void allocate();
    int width_ = 0, height_ = 0;
    GlTexture color_, fibers_, depth_;
    GlFramebuffer framebuffer_;
};

}  // namespace fiblet::viewer
