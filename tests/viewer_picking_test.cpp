// Picking through the 32-bit fiber buffer: the fiber under a pixel is the
// one drawn there, with its ID, point count and length.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fiber_picking.hpp"
#include "gpu_scene.hpp"
#include "orbit_camera.hpp"
#include "render_target.hpp"
#include "renderer.hpp"
#include "viewer_test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;

TEST(ViewerPicking, KnownFibersSeenFromAbove) {
    FIBLET_REQUIRE_GL();
    // Six straight fibers along x, 8 mm apart in y, of different lengths.
    std::vector<std::vector<Vec3f>> fibers;
    for (int k = 0; k < 6; ++k) {
        std::vector<Vec3f> f;
        const int points = 150 + 37 * k;
        for (int i = 0; i < points; ++i) f.push_back({-15 + 0.1f * float(i), -20 + 8 * float(k), 0.3f * float(k)});
        fibers.push_back(f);
    }
    const CompressedScene compressed(fibers);
    const FftFile& file = compressed.file;
    const viewer::GpuScene& scene = compressed.scene;
    viewer::Renderer renderer(*viewer_gl().programs);
    viewer::RenderTarget target(200, 160);
    const Camera cam = viewer::camera_from_spec("top", scene, 200.0f / 160.0f, 35, 1);
    renderer.render(scene, cam, {}, target);

    const Mat4 vp = view_projection_matrix(cam);
    const auto blocks = file.read_blocks(0, file.header().blocks);
    for (std::size_t k = 0; k < fibers.size(); ++k) {
        const Vec3f mid = fibers[k][fibers[k].size() / 2];
        const Projected p = to_window(clip_of(vp, mid), 200, 160);
        const auto picked = viewer::pick_fiber(target, scene, int(p.x), int(p.y), 2);
        ASSERT_TRUE(picked.has_value()) << "fiber " << k;
        const std::uint32_t stored_id = BlockView{&blocks[file.first_block(k) * file.header().block_bytes()]}.fiber_id();
        EXPECT_EQ(picked->index, k);
        EXPECT_EQ(picked->id, stored_id);
        EXPECT_EQ(picked->points, fibers[k].size());
        EXPECT_NEAR(picked->length_mm, 0.1 * double(fibers[k].size() - 1), 1e-3);
    }
    // Nothing in the corners.
    EXPECT_FALSE(viewer::pick_fiber(target, scene, 0, 0, 2).has_value());
    EXPECT_FALSE(viewer::pick_fiber(target, scene, 199, 159, 2).has_value());
}

// A transparent frame leaves no fiber indices: pick_fiber_in_frame draws it
// opaque to pick from (issue 16).
TEST(ViewerPicking, PicksUnderATransparentFrame) {
    FIBLET_REQUIRE_GL();
    std::vector<std::vector<Vec3f>> fibers;
    for (int k = 0; k < 4; ++k) {
        std::vector<Vec3f> f;
        for (int i = 0; i < 200; ++i) f.push_back({-10 + 0.1f * float(i), -12 + 8 * float(k), 0.5f * float(k)});
        fibers.push_back(f);
    }
    const CompressedScene compressed(fibers);
    const viewer::GpuScene& scene = compressed.scene;
    viewer::Renderer renderer(*viewer_gl().programs);
    viewer::RenderTarget target(200, 160);
    const Camera cam = viewer::camera_from_spec("top", scene, 200.0f / 160.0f, 35, 1);
    for (const auto style : {viewer::DrawStyle::lines, viewer::DrawStyle::capsules}) {
        viewer::RenderOptions o;
        o.style = style;
        o.opacity = 0.3f;
        const Mat4 vp = view_projection_matrix(cam);
        for (std::size_t k = 0; k < fibers.size(); ++k) {
            renderer.render(scene, cam, o, target);
            const Projected p = to_window(clip_of(vp, fibers[k][100]), 200, 160);
            EXPECT_FALSE(viewer::pick_fiber(target, scene, int(p.x), int(p.y), 2).has_value()) << "no indices";
            const auto picked = viewer::pick_fiber_in_frame(renderer, scene, cam, o, target, int(p.x), int(p.y), 2);
            ASSERT_TRUE(picked.has_value()) << viewer::draw_style_name(style) << " fiber " << k;
            EXPECT_EQ(picked->index, k);
        }
    }
}

TEST(ViewerPicking, PickedFiberPassesThroughThePixel) {
    FIBLET_REQUIRE_GL();
    const FftFile file(shared_data("reference/small-sdstream.fft"));
    const viewer::GpuScene scene(file, *viewer_gl().programs);
    viewer::Renderer renderer(*viewer_gl().programs);
    const int w = 200, h = 200;
    viewer::RenderTarget target(w, h);
    const Camera cam = viewer::camera_from_spec("oblique", scene, 1.0f, 35, 1);
    viewer::RenderOptions o;
    o.level_of_detail = false;
    renderer.render(scene, cam, o, target);

    const Streamlines lines = decode_fibers(file, 0, file.header().fibers);
    const Mat4 vp = view_projection_matrix(cam);
    std::mt19937 rng(5);
    std::uniform_int_distribution<int> ux(0, w - 1), uy(0, h - 1);
    int checked = 0;
    for (int attempt = 0; attempt < 2000 && checked < 100; ++attempt) {
        const int x = ux(rng), y = uy(rng);
        const auto picked = viewer::pick_fiber(target, scene, x, y, 0);
        if (!picked) continue;
        ++checked;
        // Some segment of the picked fiber (CPU decoded) crosses that pixel.
        double best = 1e30;
        for (std::uint64_t i = lines.offsets[picked->index]; i + 1 < lines.offsets[picked->index + 1]; ++i) {
            const Vec3f a{lines.xyz[3 * i], lines.xyz[3 * i + 1], lines.xyz[3 * i + 2]};
            const Projected p = to_window(clip_of(vp, a), w, h);
            best = std::min(best, std::hypot(p.x - (x + 0.5), p.y - (y + 0.5)));
        }
        EXPECT_LT(best, 1.5) << "pixel " << x << "," << y << " fiber " << picked->index;
    }
    EXPECT_EQ(checked, 100);
}
