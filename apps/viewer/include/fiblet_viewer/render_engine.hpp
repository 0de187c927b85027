// What turns the fibers into pixels: the rasterizing renderer with its
// drawing styles (techniques/), or the voxel ray tracer (voxel_rt/).
// Renderer::render is the one place that chooses between them.
#pragma once

#include <optional>
#include <string>

namespace fiblet::viewer {

enum class RenderEngine { raster, voxel_rt };

const char* render_engine_name(RenderEngine engine);  // "raster", "voxel-rt"
std::optional<RenderEngine> parse_render_engine(const std::string& name);
std::string render_engine_names();  // "raster, voxel-rt"

}  // namespace fiblet::viewer
