// What a frame draws and how, and what it measured.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "fiblet_viewer/colormap_name.hpp"
#include "fiblet_viewer/gpu_decoder.hpp"
#include "fiblet_viewer/draw_style.hpp"
#include "fiblet_viewer/render_engine.hpp"
#include "fiblet/view.hpp"
#include "fiblet_viewer/transparency_mode.hpp"

namespace fiblet::viewer {

inline constexpr std::size_t kMaxHighlightedFibers = 64;  // fiber_colors.glsl's kMaxHighlighted
inline constexpr int kMaxSupersample = 8;  // render_supersampled's largest factor (render/supersampling.hpp)

struct RenderOptions {
    RenderEngine engine = RenderEngine::raster;

    // Per-frame selection on the GPU (fiblet/view.hpp definitions).
    bool frustum_culling = true;
    bool level_of_detail = true;
    float lod_pixels = kDefaultLodPixels;
    // Fiber subset: IDs in [id_min, id_max], nominal lengths in [min, max] mm.
    std::uint32_t id_min = 0, id_max = std::numeric_limits<std::uint32_t>::max();
    double min_length_mm = 0, max_length_mm = std::numeric_limits<double>::infinity();

    std::optional<GpuDecoder> decoder;  // unset: default_decoder()

    // Drawing style (techniques/) and shading.
    DrawStyle style = DrawStyle::lines;
    float tube_radius_mm = 0.25f;                      // tubes and capsules
    bool fiber_radii = false;                          // the scene's per-fiber radii instead (GpuScene::set_fiber_radii), when it has them
    bool color_by_direction = true;                    // |direction| as RGB, else fixed_color
    std::array<float, 3> fixed_color{0.95f, 0.85f, 0.6f};
    bool fiber_colors = false;                         // the scene's per-fiber colours (GpuScene::set_fiber_colors), when it has them
    // The scene's per-point values (GpuScene::set_point_values), when it has
    // them, through `colormap` over `value_range` (default: the values'
    // min..max); before per-fiber colours. Lines (not voxlines), tubes and
    // capsules; not the voxel ray tracer.
    bool point_values = false;
    ColormapName colormap = ColormapName::viridis;
    std::optional<std::array<float, 2>> value_range;
    bool color_bar = true;                             // the colour bar of the point values, when they are on
    std::string value_name;                            // under the colour bar
    // Fibers drawn as they are while every other is dimmed (picking; at
    // most kMaxHighlightedFibers, sorted, unique); empty: none dimmed.
    std::vector<std::uint32_t> highlighted_fibers;
    bool lighting = true;                              // illuminated lines
    bool color_by_normal = false;                      // ray-cast styles: unit normal n as RGB (n + 1) / 2 (checks)
    float line_width = 1;                              // pixels
    std::array<float, 3> background{0, 0, 0};
    // --slab: only fibers within slab_half_width_mm of the plane n·x = d
    // (slab_plane = n, d; world mm); 0: no slab.
    std::array<float, 4> slab_plane{0, 0, 1, 0};
    float slab_half_width_mm = 0;
    // Transparency: every fragment blends with this opacity (0 < opacity <= 1),
    // times its fiber's own with fiber_opacity, ordered by `transparency`
    // (transparency/); 1 without fiber_opacity draws opaque.
    float opacity = 1.0f;
    bool fiber_opacity = false;  // the scene's per-fiber opacities (GpuScene::set_fiber_opacities), when it has them
    TransparencyMode transparency = TransparencyMode::sorted;
    // Voxel ray tracer (engine voxel_rt; capsules of tube_radius_mm).
    int voxel_grid = 128;            // voxels along each side of its cubic grid
    bool ambient_occlusion = false;  // 12 cones through the occupancy pyramid
    bool shadows = false;            // one shadow ray towards the headlight
    bool empty_space_skipping = true;  // rays skip empty cells of the occupancy / culling pyramid (false: voxel by voxel)
    bool clear = true;  // clear the target first (false: draw over what it holds, depth included)

    bool time_stages = false;       // time cull / decode / draw (GpuTimer, default_timing_method)
    bool record_decisions = false;  // keep each block's culling decision (Renderer::read_decisions)

    bool transparent() const { return opacity < 1.0f || fiber_opacity; }
    bool subset_active() const {
        return id_min > 0 || id_max < std::numeric_limits<std::uint32_t>::max() || min_length_mm > 0 ||
               max_length_mm < std::numeric_limits<double>::infinity();
    }
};

struct FrameStats {
    std::uint64_t tested_blocks = 0;  // blocks the selection pass tested (0: every block drawn untested)
    std::uint64_t fine_blocks = 0, coarse_blocks = 0;      // blocks drawn in full / as one segment
    std::uint64_t fine_segments = 0, coarse_segments = 0;  // line segments drawn
    double cull_ms = 0, decode_ms = 0, draw_ms = 0;         // GPU time (time_stages)
    std::uint64_t drawn_blocks() const { return fine_blocks + coarse_blocks; }
    // Tested and not drawn: outside the view frustum, or left out by the fiber subset.
    std::uint64_t skipped_blocks() const { return tested_blocks - std::min(tested_blocks, drawn_blocks()); }
    std::uint64_t drawn_segments() const { return fine_segments + coarse_segments; }
};

}  // namespace fiblet::viewer
