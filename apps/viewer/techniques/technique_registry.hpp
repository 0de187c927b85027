// The one place that maps render options to modules: a drawing style to its
// technique (techniques/), a transparency mode to the order its blocks are
// drawn in (transparency/), and the engine (raster or the voxel ray tracer).
// Nothing else in the viewer switches on a style, mode or engine.
#pragma once

#include <map>
#include <memory>
#include <span>
#include <string>

#include "fiblet_viewer/draw_style.hpp"
#include "fiblet_viewer/render_options.hpp"
#include "scene/gpu_programs.hpp"
#include "techniques/draw_technique.hpp"
#include "techniques/frame_order.hpp"

namespace fiblet::viewer {

// Whether the frame is the voxel ray tracer's (voxel_rt/), which selects and
// decodes for itself, rather than the raster pipeline's.
bool ray_traced(const RenderOptions& options);
// What the window's keys cycle through and its panel offers.
DrawStyle next_style(DrawStyle style);
RenderEngine next_engine(RenderEngine engine);
std::span<const DrawStyle> draw_styles();
std::span<const RenderEngine> render_engines();
std::span<const TransparencyMode> transparency_modes();
// Whether `mode` orders the blending of `style` (voxlines: lines only;
// plan() falls back to sorted chunks for the others).
bool orders_style(TransparencyMode mode, DrawStyle style);
// Whether the frame's technique reads the radius / the line width.
bool uses_radius(const RenderOptions& options);
bool uses_line_width(const RenderOptions& options);
// "tubes", "voxel-rt": what draws, for titles and reports.
std::string technique_label(const RenderOptions& options);

// A frame's fine blocks: drawn by `technique` in `order`.
struct FramePlan {
    DrawTechnique& technique;
    FrameOrder& order;
};

// The modules of one GL context, each compiled on first use; their
// compilation throws fiblet::Error{unsupported} as build_program does.
class TechniqueRegistry {
public:
    explicit TechniqueRegistry(const GpuPrograms& programs) : programs_(programs) {}

    // The style's module: culling margins and coarse blocks.
    DrawTechnique& style(DrawStyle style);
    // Blending lines draw as TransparentLines; sorted blending needs a
    // technique that draws chunks, else blocks blend in list order.
    FramePlan plan(const RenderOptions& options);
    // Draws `style` with `technique` from now on (tests: other parameters).
    void replace(DrawStyle style, std::unique_ptr<DrawTechnique> technique) {
        styles_[style] = std::move(technique);
    }
    // GPU memory the transparency orders keep between frames.
    std::uint64_t order_bytes() const;

private:
    DrawTechnique& blending(DrawStyle style);

    const GpuPrograms& programs_;
    std::map<DrawStyle, std::unique_ptr<DrawTechnique>> styles_;
    std::unique_ptr<DrawTechnique> transparent_lines_;
    ListOrder list_order_;
    std::unique_ptr<FrameOrder> sorted_chunks_, voxlines_;
};

}  // namespace fiblet::viewer
