#include "fiblet_viewer/render_engine.hpp"

#include <array>
#include <utility>

namespace fiblet::viewer {

namespace {
constexpr std::array kEngines{std::pair{RenderEngine::raster, "raster"}, std::pair{RenderEngine::voxel_rt, "voxel-rt"}};
}  // namespace

const char* render_engine_name(RenderEngine engine) {
    for (const auto& [e, name] : kEngines)
        if (e == engine) return name;
    return "?";
}

std::optional<RenderEngine> parse_render_engine(const std::string& name) {
    for (const auto& [e, n] : kEngines)
        if (name == n) return e;
    return std::nullopt;
}

std::string render_engine_names() {
    std::string out;
    for (const auto& [e, name] : kEngines) out += (out.empty() ? "" : ", ") + std::string(name);
    return out;
}

}  // namespace fiblet::viewer
