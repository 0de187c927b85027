#include "overlays/color_bar/color_bar.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "gl/gpu_bindings.hpp"
#include "gl/shader_program.hpp"
#include "overlays/color_bar/color_bar_font.hpp"
#include "render/shading_uniforms.hpp"

namespace fiblet::viewer {

ColorBarLayout color_bar_layout(int width, int height) {
    ColorBarLayout l;
    l.scale = std::max(1.0f, std::round(float(height) / 256.0f));
    const float s = l.scale, margin = 4 * s;
    l.cells = std::clamp(int((float(width) - 2 * margin) / (4 * s)), 0, std::min(kColorBarMaxCells, 48));
    const float w = float(l.cells) * 4 * s, x0 = std::floor((float(width) - w) / 2);
    l.box = {x0, margin, x0 + w, margin + 15 * s};
    l.gradient = {x0, margin + 7 * s, x0 + w, margin + 15 * s};
    return l;
}

std::string color_bar_labels(float low, float high, const std::string& name, int cells) {
    const std::string lo = fmt::format("{:.3g}", low), hi = fmt::format("{:.3g}", high);
    std::string line(std::size_t(std::max(cells, 0)), ' ');
    if (lo.size() + hi.size() + 1 > line.size()) return line;
    line.replace(0, lo.size(), lo);
    line.replace(line.size() - hi.size(), hi.size(), hi);
    const std::size_t free = line.size() - lo.size() - hi.size();
    if (!name.empty() && name.size() + 2 <= free) {
        const std::size_t at = std::clamp((line.size() - name.size()) / 2, lo.size() + 1, line.size() - hi.size() - 1 - name.size());
        line.replace(at, name.size(), name);
    }
    return line;
}

ColorBar::ColorBar()
    : program_(build_program({"color_bar.vert.glsl", "color_bar.frag.glsl"}, gpu_binding_defines())) {}

void ColorBar::draw(int width, int height, const RenderOptions& o) {
    const ColorBarLayout l = color_bar_layout(width, height);
    if (l.cells < 8) return;  // no room for the labels
    const std::array<float, 2> range = o.value_range.value_or(std::array<float, 2>{0, 1});
    const std::vector<std::uint32_t> glyphs = glyph_line(color_bar_labels(range[0], range[1], o.value_name, l.cells));
    const GLuint id = program_.get();
    set_colormap_uniforms(program_, o);
    glProgramUniform2f(id, uniform(program_, "uViewport"), float(width), float(height));
    glProgramUniform4fv(id, uniform(program_, "uBox"), 1, l.box.data());
    glProgramUniform4fv(id, uniform(program_, "uGradient"), 1, l.gradient.data());
    glProgramUniform1f(id, uniform(program_, "uScale"), l.scale);
    glProgramUniform1i(id, uniform(program_, "uCells"), l.cells);
    glProgramUniform1uiv(id, uniform(program_, "uGlyphs"), GLsizei(glyphs.size()), glyphs.data());
    glUseProgram(id);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
}

}  // namespace fiblet::viewer
