// Colour maps as 17 anchors (t = 0, 1/16 .. 1, sampled from matplotlib's
// 256-entry tables), linearly interpolated: the shaders (fiber_colors.glsl's
// colormapColor) receive the same anchors and interpolate the same way.
#pragma once

#include <array>
#include <span>

#include "fiblet_viewer/colormap_name.hpp"

namespace fiblet::viewer {

inline constexpr int kColormapAnchors = 17;  // fiber_colors.glsl's kColormapAnchors
using ColormapAnchors = std::array<std::array<float, 3>, kColormapAnchors>;

// Every map, in the order the panel offers them.
std::span<const ColormapName> colormaps();
const ColormapAnchors& colormap_anchors(ColormapName map);

// The map at t in [0, 1] (clamped; NaN maps to 0).
std::array<float, 3> colormap_color(ColormapName map, float t);

// t of `value` over [low, high], clamped; 0.5 when the range is empty.
float colormap_position(float value, float low, float high);

}  // namespace fiblet::viewer
