// The window's control panel, driven through Dear ImGui's own input as a
// user's clicks are (no window, no GL: ImGui lays out and takes input
// without drawing). Each test clicks a control by the rectangle the panel
// recorded for it and checks what the options became.
#include <gtest/gtest.h>
#include <imgui.h>

#include <string>

#include "window/control_panel.hpp"

namespace fiblet::viewer {
namespace {

class PanelDriver {
public:
    PanelDriver() {
        context_ = ImGui::CreateContext();
        ImGuiIO& io = ImGui::GetIO();
        io.IniFilename = nullptr;
        io.DisplaySize = ImVec2(1280, 900);
        io.DeltaTime = 1.0f / 60;
        unsigned char* pixels = nullptr;
        int w = 0, h = 0;
        io.Fonts->GetTexDataAsRGBA32(&pixels, &w, &h);  // the font atlas: laid out, never uploaded
    }
    ~PanelDriver() { ImGui::DestroyContext(context_); }

    // One ImGui frame of the panel with the mouse at (x, y), the button down or up.
    PanelRequests frame(float x = -1, float y = -1, bool down = false) {
        ImGuiIO& io = ImGui::GetIO();
        io.MousePos = ImVec2(x, y);
        io.MouseDown[0] = down;
        ImGui::NewFrame();
        const PanelRequests r = panel.draw(options, overlays, scene, info, &layout);
        ImGui::Render();
        return r;
    }
    // Clicks the control recorded as `label`; the requests of the release frame.
    PanelRequests click(const std::string& label) {
        frame();
        const auto at = layout.find(label);
        if (at == layout.end()) {
            ADD_FAILURE() << "the panel shows no control " << label;
            return {};
        }
        const float x = (at->second.first[0] + at->second.second[0]) / 2;
        const float y = (at->second.first[1] + at->second.second[1]) / 2;
        frame(x, y, false);
        frame(x, y, true);
        PanelRequests r = frame(x, y, false);
        frame();  // the mouse leaves; the layout follows the change
        return r;
    }
    bool shows(const std::string& label) {
        layout.clear();
        frame();
        return layout.count(label) > 0;
    }

    ControlPanel panel;
    RenderOptions options;
    OverlaySources overlays;
    PanelScene scene;
    PanelFrame info;
    PanelLayout layout;

private:
    ImGuiContext* context_;
};

TEST(ViewerControlPanel, EngineStyleAndTheirSettings) {
    PanelDriver d;
    EXPECT_TRUE(d.shows("line width (px)"));
    EXPECT_FALSE(d.shows("radius (mm)"));
    EXPECT_TRUE(d.click("style/capsules").render);
    EXPECT_EQ(d.options.style, DrawStyle::capsules);
    EXPECT_TRUE(d.shows("radius (mm)"));
    EXPECT_FALSE(d.shows("line width (px)"));
    EXPECT_FALSE(d.shows("shadows"));
    EXPECT_TRUE(d.click("engine/voxel-rt").render);
    EXPECT_EQ(d.options.engine, RenderEngine::voxel_rt);
    EXPECT_FALSE(d.shows("style/lines"));  // the ray tracer draws capsules only
    EXPECT_TRUE(d.click("shadows").render);
    EXPECT_TRUE(d.options.shadows);
    EXPECT_TRUE(d.click("ambient occlusion").render);
    EXPECT_TRUE(d.options.ambient_occlusion);
    // A click that changes nothing asks for no frame.
    EXPECT_FALSE(d.click("engine/voxel-rt").render);
}

TEST(ViewerControlPanel, TransparencyModesFollowTheStyle) {
    PanelDriver d;
    EXPECT_FALSE(d.shows("transparency/sorted"));  // opaque: no order to choose
    d.options.opacity = 0.5f;
    EXPECT_TRUE(d.shows("transparency/voxlines"));
    EXPECT_TRUE(d.click("transparency/voxlines").render);
    EXPECT_EQ(d.options.transparency, TransparencyMode::voxlines);
    // Voxlines order lines only: tubes take the first mode that orders them.
    d.click("style/tubes");
    EXPECT_FALSE(d.shows("transparency/voxlines"));
    EXPECT_EQ(d.options.transparency, TransparencyMode::sorted);
    EXPECT_TRUE(d.click("transparency/unsorted").render);
    EXPECT_EQ(d.options.transparency, TransparencyMode::unsorted);
}

TEST(ViewerControlPanel, ColourModesAreThoseTheSceneHas) {
    PanelDriver d;
    EXPECT_FALSE(d.shows("colour/per fiber"));
    EXPECT_FALSE(d.shows("colour/per point"));
    EXPECT_TRUE(d.click("colour/constant").render);
    EXPECT_FALSE(d.options.color_by_direction);
    EXPECT_TRUE(d.shows("colour"));  // the constant's colour editor

    d.scene.fiber_colors = d.scene.point_values = true;
    d.scene.point_value_range = {0.2f, 0.9f};
    EXPECT_TRUE(d.click("colour/per point").render);
    EXPECT_TRUE(d.options.point_values);
    EXPECT_FALSE(d.options.fiber_colors);
    EXPECT_TRUE(d.click("colormap/magma").render);
    EXPECT_EQ(d.options.colormap, ColormapName::magma);
    EXPECT_TRUE(d.click("colour bar").render);
    EXPECT_FALSE(d.options.color_bar);
    EXPECT_TRUE(d.click("colour/per fiber").render);
    EXPECT_TRUE(d.options.fiber_colors);
    EXPECT_FALSE(d.options.point_values);
    EXPECT_TRUE(d.click("colour/direction").render);
    EXPECT_TRUE(d.options.color_by_direction);
    EXPECT_FALSE(d.options.fiber_colors);
}

TEST(ViewerControlPanel, OverlaysAreMadeAgainWhenASliceChanges) {
    PanelDriver d;
    EXPECT_FALSE(d.shows("glyphs/slice"));  // nothing over the fibers: no section
    d.overlays.odf_path = "fod.nii";
    d.overlays.odf_slice = {2, 4};
    EXPECT_TRUE(d.shows("glyphs/slice"));
    EXPECT_FALSE(d.shows("image/slice"));
    const PanelRequests axis = d.click("glyphs/axis/x");
    EXPECT_TRUE(axis.overlays);
    EXPECT_TRUE(axis.render);
    EXPECT_EQ(d.overlays.odf_slice.axis, 0);
    EXPECT_EQ(d.overlays.odf_slice.index, -1);  // a new axis starts at its middle
    // The field's "+" button: the last square before its label.
    d.frame();
    const auto [lo, hi] = d.layout.at("glyphs/slice");
    const float label = ImGui::CalcTextSize(kSliceLabel).x + ImGui::GetStyle().ItemInnerSpacing.x;
    d.layout["glyphs/slice/+"] = {{hi[0] - label - ImGui::GetFrameHeight(), lo[1]}, {hi[0] - label, hi[1]}};
    EXPECT_TRUE(d.click("glyphs/slice/+").overlays);
    EXPECT_EQ(d.overlays.odf_slice.index, 0);
    EXPECT_TRUE(d.click("glyphs/slice/+").overlays);
    EXPECT_EQ(d.overlays.odf_slice.index, 1);
}

TEST(ViewerControlPanel, SelectionButtonsAskTheWindow) {
    PanelDriver d;
    d.scene.fiber_values = {{"dps/weight", {0.5f, 2.5f, 4.0f}}};
    d.info.picked = PickedFiber{1, 7, 57, 135.16, 10, 10};
    d.info.highlighted = 1;
    d.options.highlighted_fibers = {1};
    EXPECT_TRUE(d.click("clear").clear_selection);
    EXPECT_TRUE(d.click("save selection (W)").save_selection);
}

}  // namespace
}  // namespace fiblet::viewer
