// fiblet view IN — the interactive viewer (needs a display).
#include "cli_common.hpp"
#include "viewer_options.hpp"
#include "fiblet_viewer/viewer_window.hpp"

namespace fiblet::cli {
namespace {

void run(const ViewerArgs& a, const std::string& save_selection) {
    viewer::WindowOptions o;
    if (!save_selection.empty()) o.selection_path = save_selection;
    parse_size(a.size, o.width, o.height);
    o.render = render_options_from(a);
    o.camera = a.camera, o.fov_y_deg = a.fov, o.zoom = a.zoom;
    o.gpu_budget_bytes = gpu_budget_bytes(a);
    o.screenshot_supersample = a.supersample;
    o.fiber_colors = fiber_color_source(a);
    o.fiber_radii_path = a.fiber_radii;
    o.fiber_opacity_source = a.fiber_opacity;
    o.overlays = overlay_sources_from(a);
    viewer::run_viewer_window(a.input, o);
}

}  // namespace

void add_view(CLI::App& app) {
    auto args = std::make_shared<ViewerArgs>();
    auto selection = std::make_shared<std::string>();
    args->size = "1280x800";
    CLI::App* cmd = app.add_subcommand("view", "Show a .fft (or .tck) file in a window (needs a display)");
    add_viewer_options(cmd, *args);
    cmd->add_option("--size", args->size, "Window size WIDTHxHEIGHT")->capture_default_str();
    cmd->add_option("--save-selection", *selection,
                    "Where W saves the highlighted (picked) fibers, as the list extract --fibers and --highlight read "
                    "(default fiblet-selection.txt)");
    cmd->footer(std::string("Controls:\n") + viewer::window_controls_help());
    cmd->callback([args, selection] { run(*args, *selection); });
}

}  // namespace fiblet::cli
