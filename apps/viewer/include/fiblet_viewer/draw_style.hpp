// How fibers are drawn: one technique module each (techniques/).
#pragma once

#include <optional>
#include <string>

namespace fiblet::viewer {

enum class DrawStyle {
    lines,  // illuminated lines (techniques/lines)
    tubes,     // ray-cast spline tubes (techniques/tubes)
    capsules,  // ray-cast capsules, one per decoded segment (techniques/capsules)
};

const char* draw_style_name(DrawStyle style);
std::optional<DrawStyle> parse_draw_style(const std::string& name);
// "lines, tubes" for messages and help.
std::string draw_style_names();

}  // namespace fiblet::viewer
