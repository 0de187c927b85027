// The colour bar of the per-point values (RenderOptions::point_values and
// color_bar): the colour map's gradient along the frame's bottom edge, with
// the range's ends and the values' name under it in a bitmap font. Drawn
// by Renderer::render after everything else, in window pixels; it writes
// fiber 0 (not a fiber) where it covers the frame.
#pragma once

#include <array>
#include <string>

#include "gl/gl_objects.hpp"
#include "fiblet_viewer/render_options.hpp"

namespace fiblet::viewer {

inline constexpr int kColorBarMaxCells = 128;  // color_bar.frag.glsl's kMaxCells

// Where the bar lies in a width x height frame (pixels from the bottom-left).
struct ColorBarLayout {
    float scale = 1;                 // pixels per glyph pixel
    std::array<float, 4> box{};      // x0 y0 x1 y1: all of it
    std::array<float, 4> gradient{}; // x0 y0 x1 y1: the colours
    int cells = 0;                   // characters in the label line
};
ColorBarLayout color_bar_layout(int width, int height);

// The label line of `cells` characters: `low` at the left, `high` at the
// right, `name` centred (left out when it does not fit between them).
std::string color_bar_labels(float low, float high, const std::string& name, int cells);

class ColorBar {
public:
    ColorBar();
    // Draws over the bound framebuffer (width x height), depth test off.
    void draw(int width, int height, const RenderOptions& options);

private:
    GlProgram program_;
};

}  // namespace fiblet::viewer
