// `fiblet view`: the renderer in a window (GLFW, OpenGL 4.5 core), with an
// orbit / pan / zoom camera, picking and screenshots. Needs a display.
#pragma once

#include <string>

#include "fiblet_viewer/render_options.hpp"
#include "fiblet_viewer/scene_sources.hpp"

namespace fiblet::viewer {

struct WindowOptions {
    int width = 1280, height = 800;
    std::string camera = "oblique";  // as camera_from_spec
    float fov_y_deg = 35, zoom = 1;
    RenderOptions render;
    std::string screenshot_prefix = "fiblet-screenshot";  // + "-NNN.png" in the working directory
    int screenshot_supersample = 1;  // screenshots drawn again, supersampled (supersampling.hpp)
    std::string selection_path = "fiblet-selection.txt";  // where W saves the highlighted fibers
    FiberColorSource fiber_colors;  // render.fiber_colors turns them on
    OverlaySources overlays;        // glyphs and slices over the fibers
    std::string fiber_radii_path;   // fiber_radii.hpp; render.fiber_radii turns them on
    std::string fiber_opacity_source;  // fiber_opacity.hpp; render.fiber_opacity turns them on
    // GPU memory the scene may take (scene/fiber_streaming.hpp); 0: a share
    // of what the driver reports. A file beyond it shows a sparse overview
    // first, then, once the view rests, the fibers it sees, as many as fit.
    std::uint64_t gpu_budget_bytes = 0;
};

// The key and mouse bindings, for --help and the H key.
const char* window_controls_help();

// Opens a window, then the .fft or .tck file at `path` (open_scene_file), and
// returns when the window is closed. Throws fiblet::Error{unsupported} when
// no window can be opened (no display), before reading the file.
void run_viewer_window(const std::string& path, const WindowOptions& options);

}  // namespace fiblet::viewer
