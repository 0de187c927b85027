#include "techniques/technique_registry.hpp"

#include <algorithm>

#include "render/option_names.hpp"
#include "techniques/capsules/capsules_technique.hpp"
#include "techniques/lines/lines_technique.hpp"
#include "techniques/tubes/tubes_technique.hpp"
#include "transparency/sorted_chunks.hpp"
#include "transparency/transparent_lines.hpp"
#include "transparency/voxlines.hpp"

namespace fiblet::viewer {

namespace {

// In the order the window's T key cycles them.
constexpr auto kStyles = option_names(std::pair{DrawStyle::lines, "lines"}, std::pair{DrawStyle::tubes, "tubes"},
                                      std::pair{DrawStyle::capsules, "capsules"});
constexpr auto kStyleList = kStyles.values();

std::unique_ptr<DrawTechnique> make_technique(DrawStyle style) {
    switch (style) {
        case DrawStyle::lines: return std::make_unique<LinesTechnique>();
        case DrawStyle::tubes: return std::make_unique<TubesTechnique>();
        case DrawStyle::capsules: return std::make_unique<CapsulesTechnique>();
    }
    return nullptr;
}

}  // namespace

const char* draw_style_name(DrawStyle style) { return kStyles.name(style); }
std::optional<DrawStyle> parse_draw_style(const std::string& name) { return kStyles.parse(name); }
std::string draw_style_names() { return kStyles.names(); }

bool ray_traced(const RenderOptions& options) { return options.engine == RenderEngine::voxel_rt; }

DrawStyle next_style(DrawStyle style) {
    const auto styles = draw_styles();
    const auto at = std::find(styles.begin(), styles.end(), style);
    return at == styles.end() || at + 1 == styles.end() ? styles.front() : *(at + 1);
}

RenderEngine next_engine(RenderEngine engine) {
    return engine == RenderEngine::raster ? RenderEngine::voxel_rt : RenderEngine::raster;
}

std::span<const DrawStyle> draw_styles() { return kStyleList; }

// The panel's order: the default first (the names' table lists voxlines first).
std::span<const TransparencyMode> transparency_modes() {
    static constexpr std::array kList{TransparencyMode::sorted, TransparencyMode::voxlines, TransparencyMode::unsorted};
    return kList;
}

bool orders_style(TransparencyMode mode, DrawStyle style) {
    return mode != TransparencyMode::voxlines || style == DrawStyle::lines;
}

bool uses_radius(const RenderOptions& o) { return ray_traced(o) || o.style != DrawStyle::lines; }

bool uses_line_width(const RenderOptions& o) { return !ray_traced(o) && o.style == DrawStyle::lines; }

std::string technique_label(const RenderOptions& options) {
    return ray_traced(options) ? render_engine_name(options.engine) : draw_style_name(options.style);
}

DrawTechnique& TechniqueRegistry::style(DrawStyle style) {
    auto& t = styles_[style];
    if (!t) t = make_technique(style);
    return *t;
}

DrawTechnique& TechniqueRegistry::blending(DrawStyle s) {
    if (s != DrawStyle::lines) return style(s);
    if (!transparent_lines_) transparent_lines_ = std::make_unique<TransparentLines>();
    return *transparent_lines_;
}

FramePlan TechniqueRegistry::plan(const RenderOptions& o) {
    if (!o.transparent()) return {style(o.style), list_order_};
    DrawTechnique& technique = blending(o.style);
    if (o.transparency == TransparencyMode::voxlines && o.style == DrawStyle::lines) {
        if (!voxlines_) voxlines_ = std::make_unique<VoxlineOrder>(programs_);
        return {technique, *voxlines_};
    }
    if (o.transparency == TransparencyMode::unsorted || !technique.draws_chunks()) return {technique, list_order_};
    if (!sorted_chunks_) sorted_chunks_ = std::make_unique<SortedChunks>();
    return {technique, *sorted_chunks_};
}

std::uint64_t TechniqueRegistry::order_bytes() const {
    return (sorted_chunks_ ? sorted_chunks_->gpu_bytes() : 0) + (voxlines_ ? voxlines_->gpu_bytes() : 0);
}

}  // namespace fiblet::viewer
