#include "window/control_panel.hpp"

#include <imgui.h>

#include <algorithm>
#include <span>

#include "fiblet_viewer/viewer_window.hpp"
#include "scene/colormaps.hpp"
#include "techniques/technique_registry.hpp"

namespace fiblet::viewer {

namespace {

constexpr const char* kAxes[] = {"x", "y", "z"};

// Records the last item's rectangle under `label` (tests click it).
void record(PanelLayout* layout, const std::string& label) {
    if (!layout) return;
    const ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
    (*layout)[label] = {{lo.x, lo.y}, {hi.x, hi.y}};
}

// One radio button per choice; true when the user picked another.
template <typename T, typename Name>
bool radio_row(const char* group, std::span<const T> choices, T& value, Name name, PanelLayout* layout) {
    bool changed = false;
    ImGui::PushID(group);
    for (std::size_t i = 0; i < choices.size(); ++i) {
        if (i > 0) ImGui::SameLine();
        const std::string label = name(choices[i]);
        if (ImGui::RadioButton(label.c_str(), choices[i] == value) && !(choices[i] == value)) {
            value = choices[i];
            changed = true;
        }
        record(layout, std::string(group) + "/" + label);
    }
    ImGui::PopID();
    return changed;
}

bool checkbox(const char* label, bool& value, PanelLayout* layout) {
    const bool changed = ImGui::Checkbox(label, &value);
    record(layout, label);
    return changed;
}

bool slider(const char* label, float& value, float lo, float hi, PanelLayout* layout, const char* format = "%.2f") {
    const bool changed = ImGui::SliderFloat(label, &value, lo, hi, format);
    record(layout, label);
    return changed;
}

// A slider whose value is taken when the drag ends: what it changes is
// made again (the overlays), not just drawn again.
bool slider_on_release(const char* label, float& value, float lo, float hi, const char* format, PanelLayout* layout) {
    ImGui::SliderFloat(label, &value, lo, hi, format);
    record(layout, label);
    return ImGui::IsItemDeactivatedAfterEdit();
}

bool technique_section(RenderOptions& o, PanelLayout* layout) {
    if (!ImGui::CollapsingHeader("Technique", ImGuiTreeNodeFlags_DefaultOpen)) return false;
    bool changed = radio_row("engine", render_engines(), o.engine, render_engine_name, layout);
    if (!ray_traced(o)) changed |= radio_row("style", draw_styles(), o.style, draw_style_name, layout);
    if (uses_radius(o)) changed |= slider("radius (mm)", o.tube_radius_mm, 0.02f, 2.0f, layout);
    if (uses_line_width(o)) changed |= slider("line width (px)", o.line_width, 1.0f, 16.0f, layout, "%.0f");
    changed |= slider("opacity", o.opacity, 0.02f, 1.0f, layout);
    if (o.transparent() && !ray_traced(o)) {
        std::vector<TransparencyMode> modes;
        for (const TransparencyMode m : transparency_modes())
            if (orders_style(m, o.style)) modes.push_back(m);
        if (!orders_style(o.transparency, o.style)) o.transparency = modes.front(), changed = true;
        changed |= radio_row("transparency", std::span<const TransparencyMode>(modes), o.transparency,
                             transparency_mode_name, layout);
    }
    changed |= checkbox("ambient occlusion", o.ambient_occlusion, layout);
    if (ray_traced(o)) changed |= checkbox("shadows", o.shadows, layout);
    changed |= checkbox("lighting", o.lighting, layout);
    return changed;
}

bool selection_section(RenderOptions& o, PanelLayout* layout) {
    if (!ImGui::CollapsingHeader("Level of detail", ImGuiTreeNodeFlags_DefaultOpen)) return false;
    bool changed = checkbox("frustum culling", o.frustum_culling, layout);
    changed |= checkbox("level of detail", o.level_of_detail, layout);
    if (o.level_of_detail) changed |= slider("coarse below (px)", o.lod_pixels, 0.5f, 32.0f, layout, "%.1f");
    return changed;
}

enum class ColorMode { direction, constant, fiber, point };

ColorMode color_mode(const RenderOptions& o) {
    if (o.point_values) return ColorMode::point;
    if (o.fiber_colors) return ColorMode::fiber;
    return o.color_by_direction ? ColorMode::direction : ColorMode::constant;
}

void set_color_mode(RenderOptions& o, ColorMode mode) {
    o.point_values = mode == ColorMode::point;
    o.fiber_colors = mode == ColorMode::fiber;
    o.color_by_direction = mode == ColorMode::direction;
}

bool color_section(RenderOptions& o, const PanelScene& scene, PanelLayout* layout) {
    if (!ImGui::CollapsingHeader("Colour", ImGuiTreeNodeFlags_DefaultOpen)) return false;
    std::vector<ColorMode> modes{ColorMode::direction, ColorMode::constant};
    if (scene.fiber_colors) modes.push_back(ColorMode::fiber);
    if (scene.point_values) modes.push_back(ColorMode::point);
    ColorMode mode = color_mode(o);
    const auto name = [](ColorMode m) {
        constexpr const char* kNames[] = {"direction", "constant", "per fiber", "per point"};
        return std::string(kNames[int(m)]);
    };
    bool changed = radio_row("colour", std::span<const ColorMode>(modes), mode, name, layout);
    if (changed) set_color_mode(o, mode);
    if (mode == ColorMode::constant) {
        changed |= ImGui::ColorEdit3("colour", o.fixed_color.data());
        record(layout, "colour");
    }
    if (mode == ColorMode::point) {
        changed |= radio_row("colormap", colormaps(), o.colormap, colormap_name, layout);
        std::array<float, 2> range = o.value_range.value_or(scene.point_value_range);
        const float span = std::max(range[1] - range[0], 1e-6f);
        if (ImGui::DragFloat2("value range", range.data(), span / 200.0f)) o.value_range = range, changed = true;
        record(layout, "value range");
        changed |= checkbox("colour bar", o.color_bar, layout);
    }
    return changed;
}

// A slice's axis and index: a request to make the overlays again from the
// images (the glyph scale and slab sliders ask when released).
bool slice_controls(const char* what, SliceSpec& slice, PanelLayout* layout) {
    constexpr std::array kAxisIndices{0, 1, 2};
    int axis = slice.axis, index = int(slice.index);
    bool changed = radio_row((std::string(what) + "/axis").c_str(), std::span<const int>(kAxisIndices), axis,
                             [](int a) { return std::string(kAxes[a]); }, layout);
    if (changed) slice.axis = axis, slice.index = -1;
    ImGui::PushID(what);
    // Typed values apply on Enter (each keystroke would make the overlays again); -/+ at once.
    if (ImGui::InputInt(kSliceLabel, &index, 1, 10, ImGuiInputTextFlags_EnterReturnsTrue))
        slice.index = std::max(index, -1), changed = true;
    record(layout, std::string(what) + "/slice");
    ImGui::PopID();
    return changed;
}

bool overlay_section(OverlaySources& sources, PanelLayout* layout) {
    if (!sources.any() || !ImGui::CollapsingHeader("Overlays", ImGuiTreeNodeFlags_DefaultOpen)) return false;
    bool changed = false;
    if (!sources.odf_path.empty()) {
        ImGui::TextUnformatted("ODF glyphs");
        changed |= slice_controls("glyphs", sources.odf_slice, layout);
        changed |= slider_on_release("glyph scale (voxels)", sources.odf_scale, 0.1f, 3.0f, "%.2f", layout);
    }
    if (!sources.image_path.empty()) {
        ImGui::TextUnformatted("Background image");
        changed |= slice_controls("image", sources.image_slice, layout);
    }
    changed |= slider_on_release("slab (mm, 0: all)", sources.slab_mm, 0.0f, 40.0f, "%.1f", layout);
    return changed;
}

void frame_section(const PanelFrame& f) {
    if (!ImGui::CollapsingHeader("Frame", ImGuiTreeNodeFlags_DefaultOpen)) return;
    ImGui::Text("%.1f ms (GPU cull %.1f, decode %.1f, draw %.1f)", f.frame_ms, f.stats.cull_ms, f.stats.decode_ms,
                f.stats.draw_ms);
    ImGui::Text("%llu blocks (%llu coarse), %llu segments", static_cast<unsigned long long>(f.stats.drawn_blocks()),
                static_cast<unsigned long long>(f.stats.coarse_blocks),
                static_cast<unsigned long long>(f.stats.drawn_segments()));
    ImGui::Text("GPU memory: %.2f MB (scene and transparency buffers)", double(f.gpu_bytes) / 1e6);
    if (f.fibers_held < f.file_fibers)
        ImGui::Text("fibers held: %llu of %llu (the view's, within --gpu-memory)",
                    static_cast<unsigned long long>(f.fibers_held), static_cast<unsigned long long>(f.file_fibers));
}

// The picked fiber and the selection.
PanelRequests picked_section(const PanelFrame& f, const PanelScene& scene, PanelLayout* layout) {
    PanelRequests r;
    if (!ImGui::CollapsingHeader("Picked fiber", ImGuiTreeNodeFlags_DefaultOpen)) return r;
    if (f.picked) {
        const PickedFiber& p = *f.picked;
        ImGui::Text("ID %u (index %llu)", p.id, static_cast<unsigned long long>(p.index));
        ImGui::Text("%u points, %.2f mm", p.points, p.length_mm);
        for (const auto& [name, values] : scene.fiber_values)
            if (p.index < values.size()) ImGui::Text("%s: %g", name.c_str(), double(values[p.index]));
    } else {
        ImGui::TextUnformatted("click a fiber (shift+click adds it)");
    }
    ImGui::Text("%zu highlighted", f.highlighted);
    r.save_selection = ImGui::Button("save selection (W)");
    record(layout, "save selection (W)");
    ImGui::SameLine();
    r.clear_selection = ImGui::Button("clear");
    record(layout, "clear");
    return r;
}

}  // namespace

PanelRequests ControlPanel::draw(RenderOptions& options, OverlaySources& overlays, const PanelScene& scene,
                                 const PanelFrame& frame, PanelLayout* layout) {
    PanelRequests r;
    if (show_keys) {
        ImGui::Begin("Keys", &show_keys, ImGuiWindowFlags_AlwaysAutoResize);
        ImGui::TextUnformatted(window_controls_help());
        ImGui::End();
    }
    if (!visible) return r;
    ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
    ImGui::Begin("fiblet (P hides, ? keys)", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
    frame_section(frame);
    r = picked_section(frame, scene, layout);
    r.render |= technique_section(options, layout);
    r.render |= color_section(options, scene, layout);
    r.render |= selection_section(options, layout);
    r.overlays = overlay_section(overlays, layout);
    if (!frame.message.empty()) ImGui::TextWrapped("%s", frame.message.c_str());
    ImGui::End();
    r.render |= r.overlays || r.clear_selection;
    return r;
}

}  // namespace fiblet::viewer
