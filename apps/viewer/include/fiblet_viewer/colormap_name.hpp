// The colour maps per-point values are drawn through (--colormap);
// scene/colormaps.hpp holds their tables.
#pragma once

#include <optional>
#include <string>

namespace fiblet::viewer {

enum class ColormapName { viridis, magma, coolwarm };

std::optional<ColormapName> parse_colormap(const std::string& name);  // "viridis", "magma", "coolwarm"
const char* colormap_name(ColormapName map);

}  // namespace fiblet::viewer
