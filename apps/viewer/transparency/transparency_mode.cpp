#include "fiblet_viewer/transparency_mode.hpp"

#include <array>
#include <utility>

namespace fiblet::viewer {

namespace {
constexpr std::array kModes{std::pair{TransparencyMode::voxlines, "voxlines"},
                            std::pair{TransparencyMode::sorted, "sorted"},
                            std::pair{TransparencyMode::unsorted, "unsorted"}};
}  // namespace

const char* transparency_mode_name(TransparencyMode mode) {
    for (const auto& [m, name] : kModes)
        if (m == mode) return name;
    return "?";
}

std::optional<TransparencyMode> parse_transparency_mode(const std::string& name) {
    for (const auto& [m, n] : kModes)
        if (name == n) return m;
    return std::nullopt;
}

std::string transparency_mode_names() {
    std::string out;
    for (const auto& [m, name] : kModes) out += (out.empty() ? "" : ", ") + std::string(name);
    return out;
}

}  // namespace fiblet::viewer
