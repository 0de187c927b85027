// Supersampled (anti-aliased) frames: the box filter, and renders whose
// edges take intermediate values while the image's mean stays that of the
// plain render.
#include <gtest/gtest.h>

#include "scene/gpu_scene.hpp"
#include "window/orbit_camera.hpp"
#include "render/supersampling.hpp"
#include "viewer_test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;

TEST(ViewerSupersample, BoxFilterAveragesEachBlock) {
    viewer::RgbaImage big{4, 2, {}};
    for (int i = 0; i < 8; ++i) big.rgba.insert(big.rgba.end(), {std::uint8_t(10 * i), 255, 0, 255});
    const viewer::RgbaImage small = viewer::downsample_box(big, 2);
    ASSERT_EQ(small.width, 2);
    ASSERT_EQ(small.height, 1);
    // Pixels 0, 1, 4, 5 and 2, 3, 6, 7: red 0 10 40 50 -> 25, 20 30 60 70 -> 45.
    EXPECT_EQ(small.rgba, (std::vector<std::uint8_t>{25, 255, 0, 255, 45, 255, 0, 255}));
}

namespace {
double mean_intensity(const viewer::RgbaImage& im) {
    double sum = 0;
    for (std::size_t i = 0; i < im.rgba.size(); i += 4) sum += im.rgba[i];
    return sum / double(im.rgba.size() / 4);
}
}  // namespace

TEST(ViewerSupersample, EdgesTakeIntermediateValuesAndTheMeanIsKept) {
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(shared_data("bundles/AF_L-step0.1.tck"));
    const viewer::GpuScene& scene = compressed.scene;
    viewer::Renderer renderer(*viewer_gl().programs);
    const int w = 96, h = 72;
    const Camera cam = viewer::camera_from_spec("left", scene, float(w) / float(h), 35, 1);
    for (const auto style : {viewer::DrawStyle::lines, viewer::DrawStyle::tubes}) {
        SCOPED_TRACE(viewer::draw_style_name(style));
        viewer::RenderOptions o;
        o.style = style;
        o.tube_radius_mm = 0.6f;
        o.lighting = false;
        o.color_by_direction = false;
        o.fixed_color = {1, 1, 1};  // white on black: intensity is coverage
        const auto plain = viewer::render_supersampled(renderer, scene, cam, o, w, h, 1).image;
        const auto smooth = viewer::render_supersampled(renderer, scene, cam, o, w, h, 4).image;
        ASSERT_EQ(smooth.width, w);
        ASSERT_EQ(smooth.height, h);
        std::size_t plain_between = 0, smooth_between = 0, lit = 0;
        for (std::size_t i = 0; i < plain.rgba.size(); i += 4) {
            plain_between += plain.rgba[i] != 0 && plain.rgba[i] != 255;
            smooth_between += smooth.rgba[i] != 0 && smooth.rgba[i] != 255;
            lit += smooth.rgba[i] != 0;
        }
        EXPECT_EQ(plain_between, 0u);
        EXPECT_GT(smooth_between, lit / 4);
        const double a = mean_intensity(plain), b = mean_intensity(smooth);
        std::printf("%s: mean 1x %.2f, 4x %.2f; %zu of %zu lit pixels intermediate\n",
                    viewer::draw_style_name(style), a, b, smooth_between, lit);
        EXPECT_NEAR(b, a, 0.05 * a);  // measured: within 0.4 %
    }
    EXPECT_THROW(viewer::render_supersampled(renderer, scene, cam, {}, w, h, 9), Error);
    EXPECT_THROW(viewer::render_supersampled(renderer, scene, cam, {}, 8000, 10, 4), Error);
}
