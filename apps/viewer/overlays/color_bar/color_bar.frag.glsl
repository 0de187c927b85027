#version 450
// The colour bar: the colour map from uValueRange.x (left) to .y (right)
// over its top rows, a line of 3x5-pixel glyphs (color_bar_font.hpp) under
// it: the range's ends and the values' name.
layout(location = 0) in vec2 vPixel;
layout(location = 0) out vec4 outColor;
layout(location = 1) out uint outFiber;

#include "fiber_colors.glsl"

const int kMaxCells = 128;  // ColorBar::kMaxCells
uniform vec4 uBox;          // x0 y0 x1 y1, window pixels
uniform float uScale;       // pixels per glyph pixel
uniform vec4 uGradient;     // x0 y0 x1 y1 of the gradient
uniform int uCells;
uniform uint uGlyphs[kMaxCells];  // 15 bits per cell: row r (0: top), column c at bit 14 - (3 r + c)

void main() {
    outFiber = 0u;
    if (all(greaterThanEqual(vPixel, uGradient.xy)) && all(lessThan(vPixel, uGradient.zw))) {
        float t = (vPixel.x - uGradient.x) / (uGradient.z - uGradient.x);
        outColor = vec4(colormapColor(mix(uValueRange.x, uValueRange.y, t)), 1.0);
        return;
    }
    // Text cells of 4 x 7 glyph pixels (a glyph, a gap) under the gradient.
    vec2 g = floor((vPixel - uBox.xy) / uScale) - vec2(0.0, 1.0);
    int cell = int(g.x) / 4, column = int(g.x) % 4, row = 4 - int(g.y);
    bool lit = cell < uCells && column < 3 && row >= 0 && row < 5 && g.y >= 0.0 &&
               ((uGlyphs[cell] >> uint(14 - (3 * row + column))) & 1u) != 0u;
    outColor = lit ? vec4(1.0) : vec4(0.0, 0.0, 0.0, 1.0);
}
