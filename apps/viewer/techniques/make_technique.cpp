#include "techniques/make_technique.hpp"

#include <array>

#include "techniques/capsules/capsules_technique.hpp"
#include "techniques/lines/lines_technique.hpp"
#include "techniques/tubes/tubes_technique.hpp"

namespace fiblet::viewer {

namespace {
constexpr std::array kStyles{std::pair{DrawStyle::lines, "lines"}, std::pair{DrawStyle::tubes, "tubes"},
                             std::pair{DrawStyle::capsules, "capsules"}};
}  // namespace

const char* draw_style_name(DrawStyle style) {
    for (const auto& [s, name] : kStyles)
        if (s == style) return name;
    return "?";
}

std::optional<DrawStyle> parse_draw_style(const std::string& name) {
    for (const auto& [s, n] : kStyles)
        if (name == n) return s;
    return std::nullopt;
}

std::string draw_style_names() {
    std::string out;
    for (const auto& [s, name] : kStyles) out += (out.empty() ? "" : ", ") + std::string(name);
    return out;
}

std::unique_ptr<DrawTechnique> make_technique(DrawStyle style) {
    switch (style) {
        case DrawStyle::lines: return std::make_unique<LinesTechnique>();
        case DrawStyle::tubes: return std::make_unique<TubesTechnique>();
        case DrawStyle::capsules: return std::make_unique<CapsulesTechnique>();
    }
    return nullptr;
}

}  // namespace fiblet::viewer
