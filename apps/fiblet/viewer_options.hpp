// Command-line options shared by `fiblet render` and `fiblet view`.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "fiblet_viewer/render_options.hpp"
#include "fiblet_viewer/scene_sources.hpp"

namespace fiblet::cli {

struct ViewerArgs {
    std::string input;
    std::string size = "1920x1080";
    std::string camera = "oblique";
    float fov = 35, zoom = 1;
    std::string color = "direction", background = "black", fibers, decoder = "auto";
    std::string highlight;  // fiber IDs drawn as they are, the others dimmed
    bool no_lighting = false, no_culling = false, no_lod = false;
    float lod_pixels = 4, line_width = 1;
    std::string style = "lines";
    float radius = 0.25f;
    int supersample = 1;
    std::string fiber_colors, fiber_values, value_range, fiber_radii;
    std::string point_values, colormap = "viridis";  // per-point values (a .tsf or dpv/NAME) through a colour map
    bool no_color_bar = false;
    double min_length = 0, max_length = 0;
    // Overlays: ODF glyphs of an SH image, a background image slice, a fiber slab.
    std::string odf, odf_slice, sh_basis = "mrtrix", image, slice;
    float odf_scale = 1, slab = 0;
    int odf_lmax = -1;
    float opacity = 1;
    std::string fiber_opacity;  // per-streamline opacities: a file or dps/NAME (fiber_opacity.hpp)
    double gpu_memory_mb = 0;   // the scene's GPU memory budget; 0: a share of what the driver reports
    std::string transparency;  // empty: sorted (lines) / unsorted (tubes, capsules)
    // The voxel ray tracer (--engine voxel-rt).
    std::string engine = "raster";
    int grid = 128;
    bool ao = false, shadows = false, no_empty_space_skipping = false;
};

// Adds the input file and the camera, shading and selection options.
void add_viewer_options(CLI::App* cmd, ViewerArgs& args);

// Width and height of "WxH"; throws fiblet::Error{invalid_argument}.
void parse_size(const std::string& text, int& width, int& height);

// The render options the arguments describe; throws fiblet::Error{invalid_argument}.
viewer::RenderOptions render_options_from(const ViewerArgs& args);
// --gpu-memory in bytes; 0 for the driver's share.
std::uint64_t gpu_budget_bytes(const ViewerArgs& args);

// The overlays --odf, --image and --slab ask for; throws fiblet::Error{invalid_argument}.
viewer::OverlaySources overlay_sources_from(const ViewerArgs& args);

// Where --fiber-colors / --fiber-values take the colours from; throws
// fiblet::Error{invalid_argument}.
viewer::FiberColorSource fiber_color_source(const ViewerArgs& args);

}  // namespace fiblet::cli
