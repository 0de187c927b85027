// The window's control panel (Dear ImGui): every technique, overlay and
// colour setting of `fiblet view` live, the frame's times and GPU memory,
// and what was picked. It edits the options the window renders with and
// says what changed; drawing the ImGui frame is the window's job (the panel
// is drawn after the scene is blitted, so screenshots never hold it).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fiblet_viewer/render_options.hpp"
#include "fiblet_viewer/scene_sources.hpp"
#include "window/fiber_picking.hpp"

namespace fiblet::viewer {

// What the scene offers the colour modes, and what a picked fiber shows.
struct PanelScene {
    bool fiber_colors = false, point_values = false;  // the scene has them
    std::array<float, 2> point_value_range{0, 1};
    std::uint64_t fibers = 0;
    // Per-streamline values by name (the file's dps/ fields, --fiber-values).
    std::vector<std::pair<std::string, std::vector<float>>> fiber_values;
};

// What the last frame measured, for the panel's read-outs.
struct PanelFrame {
    FrameStats stats;
    double frame_ms = 0;
    std::uint64_t gpu_bytes = 0;  // the scene's buffers and the renderer's
    std::uint64_t fibers_held = 0, file_fibers = 0;  // fewer held: a file beyond the GPU budget
    std::optional<PickedFiber> picked;
    std::size_t highlighted = 0;
    std::string message;  // the last error a change caused (e.g. a slice outside the image)
};

// What a panel frame asks of the window.
struct PanelRequests {
    bool render = false;    // an option changed: draw the scene again
    bool overlays = false;  // a slice, glyph scale or slab changed: make the overlays again
    bool save_selection = false, clear_selection = false;
};

// The slice fields' label (its -/+ buttons sit just left of it).
inline constexpr const char* kSliceLabel = "slice (-1: middle)";

// Each control's screen rectangle by label, recorded when asked (tests
// click them through ImGui's input, as a user would).
using PanelLayout = std::map<std::string, std::pair<std::array<float, 2>, std::array<float, 2>>>;

struct ControlPanel {
    bool visible = true;   // P hides and shows it
    bool show_keys = false;  // ?: the key bindings

    // Draws the panel into the current ImGui frame (between NewFrame and
    // Render) and applies what the user changed to `options` / `overlays`.
    PanelRequests draw(RenderOptions& options, OverlaySources& overlays, const PanelScene& scene,
                       const PanelFrame& frame, PanelLayout* layout = nullptr);
};

}  // namespace fiblet::viewer
