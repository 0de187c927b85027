#include "fiblet_viewer/render_engine.hpp"

#include "render/option_names.hpp"
#include "techniques/technique_registry.hpp"

namespace fiblet::viewer {

namespace {
constexpr auto kEngines =
    option_names(std::pair{RenderEngine::raster, "raster"}, std::pair{RenderEngine::voxel_rt, "voxel-rt"});
constexpr auto kEngineList = kEngines.values();
}  // namespace

const char* render_engine_name(RenderEngine engine) { return kEngines.name(engine); }
std::optional<RenderEngine> parse_render_engine(const std::string& name) { return kEngines.parse(name); }
std::string render_engine_names() { return kEngines.names(); }
std::span<const RenderEngine> render_engines() { return kEngineList; }  // technique_registry.hpp

}  // namespace fiblet::viewer
