// Picking through the 32-bit fiber buffer: the fiber under a pixel is the
// one drawn there, with its ID, point count and length.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "cli_runner.hpp"
#include "window/fiber_picking.hpp"
#include "window/fiber_selection.hpp"
#include "scene/gpu_scene.hpp"
#include "window/orbit_camera.hpp"
#include "render/render_target.hpp"
#include "render/renderer.hpp"
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

// Highlighting (issue 30): with fibers picked, the others are drawn dimmed
// in every technique, the picked ones exactly as before.
TEST(ViewerPicking, HighlightDimsEveryOtherFiberInEveryTechnique) {
    FIBLET_REQUIRE_GL();
    std::vector<std::vector<Vec3f>> fibers;
    for (int k = 0; k < 3; ++k) {
        std::vector<Vec3f> f;
        for (int i = 0; i < 200; ++i) f.push_back({-10 + 0.1f * float(i), -8 + 8 * float(k), 0.05f * float(i % 7)});
        fibers.push_back(f);
    }
    const CompressedScene compressed(fibers);
    const viewer::GpuScene& scene = compressed.scene;
    viewer::Renderer renderer(*viewer_gl().programs);
    viewer::RenderTarget target(160, 120);
    const Camera cam = viewer::camera_from_spec("top", scene, 160.0f / 120.0f, 35, 1);
    struct Case {
        const char* name;
        viewer::RenderOptions o;
    };
    std::vector<Case> cases(5);
    cases[0].name = "lines";
    cases[1].name = "tubes", cases[1].o.style = viewer::DrawStyle::tubes, cases[1].o.tube_radius_mm = 1;
    cases[2].name = "capsules", cases[2].o.style = viewer::DrawStyle::capsules, cases[2].o.tube_radius_mm = 1;
    cases[3].name = "voxel-rt", cases[3].o.engine = viewer::RenderEngine::voxel_rt, cases[3].o.tube_radius_mm = 1;
    for (Case& c : cases) c.o.lighting = false;  // the base colour alone: pixel by pixel
    cases[4].name = "tubes, lit", cases[4].o.style = viewer::DrawStyle::tubes, cases[4].o.tube_radius_mm = 1;
    for (Case& c : cases) {
        renderer.render(scene, cam, c.o, target);
        const auto plain = target.read_rgba();
        const auto ids = target.read_fibers();  // fiber index + 1, 0 for none
        c.o.highlighted_fibers = {1};
        renderer.render(scene, cam, c.o, target);
        const auto lit = target.read_rgba();
        std::size_t kept = 0, dimmed = 0, others = 0;
        for (std::size_t p = 0; p < ids.size(); ++p) {
            int before = 0, after = 0;
            for (int ch = 0; ch < 3; ++ch) before += plain[4 * p + ch], after += lit[4 * p + ch];
            if (ids[p] == 2) {  // fiber 1: unchanged
                kept += std::equal(&plain[4 * p], &plain[4 * p] + 4, &lit[4 * p]);
            } else if (ids[p] != 0) {
                ++others;
                dimmed += after * 2 <= before + 6;  // at most about half as bright (30 % of the colour, greyed)
            } else {
                EXPECT_EQ(after, before) << c.name << ": background pixel " << p;
            }
        }
        const auto count1 = std::size_t(std::count(ids.begin(), ids.end(), 2u));
        EXPECT_GT(count1, 50u) << c.name;
        EXPECT_EQ(kept, count1) << c.name;
        EXPECT_GT(others, 100u) << c.name;
        EXPECT_EQ(dimmed, others) << c.name;
    }
}

// Click, shift-click, the list W saves, and that list read back by extract.
TEST(ViewerPicking, SelectionUpdatesAndSavesAFiberList) {
    std::vector<std::uint32_t> s;
    EXPECT_TRUE(viewer::update_selection(s, 7, false));
    EXPECT_EQ(s, (std::vector<std::uint32_t>{7}));
    for (std::uint64_t f : {3u, 9u, 8u, 10u}) viewer::update_selection(s, f, true);
    EXPECT_EQ(s, (std::vector<std::uint32_t>{3, 7, 8, 9, 10}));
    viewer::update_selection(s, 8, true);  // a second shift-click takes it out
    EXPECT_EQ(s, (std::vector<std::uint32_t>{3, 7, 9, 10}));
    viewer::update_selection(s, std::nullopt, true);  // shift-click on the background keeps
    EXPECT_EQ(s.size(), 4u);
    EXPECT_EQ(viewer::fiber_list(s), "3,7,9-10\n");
    viewer::update_selection(s, std::nullopt, false);  // a click on the background clears
    EXPECT_TRUE(s.empty());
    for (std::uint64_t f = 0; f < viewer::kMaxHighlightedFibers; ++f) EXPECT_TRUE(viewer::update_selection(s, 2 * f, true));
    EXPECT_FALSE(viewer::update_selection(s, 1, true));
    EXPECT_EQ(s.size(), viewer::kMaxHighlightedFibers);

    if (!shared_data_available()) GTEST_SKIP() << "shared test data not found";
    const TempDir dir;
    const std::string fft = compress_into(dir, shared_data("bundles/CST_R.tck"), "cst.fft");
    const std::vector<std::uint32_t> picked{2, 5, 6, 7, 30};
    viewer::save_selection(dir.file("sel.txt"), picked);
    const auto r = run_cli("extract -q " + fft + " -o " + dir.file("sel.tck") + " --fibers $(cat " + dir.file("sel.txt") + ")");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(read_tck_fibers(dir.file("sel.tck")).size(), picked.size());
    const auto wide = run_cli("render " + fft + " --highlight 0-64 -o " + dir.file("x.png"));
    EXPECT_EQ(wide.status, 2);
    EXPECT_NE(wide.output.find("--highlight: at most 64 fibers"), std::string::npos) << wide.output;
}
