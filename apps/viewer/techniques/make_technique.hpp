// The one place that maps a drawing style to its technique module.
#pragma once

#include <memory>

#include "fiblet_viewer/draw_style.hpp"
#include "techniques/draw_technique.hpp"

namespace fiblet::viewer {

// Compiles the style's programs (in the current context); throws
// fiblet::Error{unsupported} as build_program does.
std::unique_ptr<DrawTechnique> make_technique(DrawStyle style);

}  // namespace fiblet::viewer
