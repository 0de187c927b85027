#include "fiblet_viewer/transparency_mode.hpp"

#include "render/option_names.hpp"

namespace fiblet::viewer {

namespace {
constexpr auto kModes = option_names(std::pair{TransparencyMode::voxlines, "voxlines"},
                                     std::pair{TransparencyMode::sorted, "sorted"},
                                     std::pair{TransparencyMode::unsorted, "unsorted"});
}  // namespace

const char* transparency_mode_name(TransparencyMode mode) { return kModes.name(mode); }
std::optional<TransparencyMode> parse_transparency_mode(const std::string& name) { return kModes.parse(name); }
std::string transparency_mode_names() { return kModes.names(); }

}  // namespace fiblet::viewer
