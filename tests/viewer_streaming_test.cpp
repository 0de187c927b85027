// Files beyond the GPU memory budget (scene/fiber_streaming.hpp): the view's
// fibers are held, thinned evenly to fit; what is drawn of them is what the
// whole file draws, and every index the viewer shows is the file's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "fiblet/block_index.hpp"
#include "render/render_target.hpp"
#include "render/renderer.hpp"
#include "scene/fiber_streaming.hpp"
#include "viewer_test_util.hpp"
#include "window/fiber_picking.hpp"

using namespace fiblet;
using namespace fiblet::test;

namespace {

constexpr int kWidth = 160, kHeight = 120;

// 240 wavy fibers of 150 points (3 blocks each), 0.2 mm apart in y, over
// y in [-24, 24).
std::vector<std::vector<Vec3f>> parallel_fibers() {
    std::vector<std::vector<Vec3f>> fibers;
    for (int k = 0; k < 240; ++k) {
        std::vector<Vec3f> f;
        const float x0 = -10.0f + float(k % 5);
        for (int i = 0; i < 150; ++i)
            f.push_back({x0 + 0.1f * float(i), -24 + 0.2f * float(k), 0.5f * std::sin(0.3f * float(i) + float(k))});
        fibers.push_back(f);
    }
    return fibers;
}

// Looking down at the fibers with y in about [-18, -6].
Camera close_up() {
    Camera c;
    c.position = {-2, -12, 30}, c.target = {-2, -12, 0}, c.up = {0, 1, 0};
    c.fov_y_deg = 25, c.aspect = float(kWidth) / float(kHeight), c.near_mm = 1, c.far_mm = 100;
    return c;
}

// What a scene takes with the renderer's per-block lists.
std::uint64_t bytes_of(const viewer::GpuScene& s) { return s.gpu_bytes() + 16ull * s.block_count(); }

struct DrawnFrame {
    std::vector<std::uint8_t> rgba;
    std::vector<std::uint64_t> file_fibers;  // per pixel: the file index + 1 of the fiber drawn, 0: none
};

DrawnFrame draw(const viewer::GpuScene& scene, const viewer::RenderOptions& o = {}, const Camera& cam = close_up()) {
    viewer::Renderer renderer(*viewer_gl().programs);
    viewer::RenderTarget target(kWidth, kHeight);
    renderer.render(scene, cam, o, target);
    DrawnFrame f{target.read_rgba(), {}};
    for (const std::uint32_t v : target.read_fibers()) f.file_fibers.push_back(v ? scene.file_fiber(v - 1) + 1 : 0);
    return f;
}

std::size_t drawn_pixels(const DrawnFrame& f) {
    return std::size_t(std::count_if(f.file_fibers.begin(), f.file_fibers.end(), [](std::uint64_t v) { return v; }));
}

// A budget of `share` of what the whole file takes.
std::uint64_t share_of_file(const FftFile& file, double share, bool point_values = false) {
    const FftHeader& h = file.header();
    return std::uint64_t(share * double(viewer::scene_gpu_bytes(h, h.fibers, h.blocks, point_values) +
                                        viewer::scene_constant_bytes(h)));
}

}  // namespace

TEST(ViewerStreaming, AFileThatFitsIsHeldWhole) {
    FIBLET_REQUIRE_GL();
    const CompressedScene whole(parallel_fibers());
    const viewer::FiberStreaming streaming(whole.file, share_of_file(whole.file, 1.0), false);
    EXPECT_FALSE(streaming.streams());
}

// Every fiber with a decoded point in the view is held when they fit, and the
// image is the whole file's, pixel for pixel.
TEST(ViewerStreaming, TheViewsFibersDrawTheWholeFilesImage) {
    FIBLET_REQUIRE_GL();
    const CompressedScene whole(parallel_fibers());
    const FftFile& file = whole.file;
    const std::uint64_t budget = share_of_file(file, 0.6);
    const viewer::FiberStreaming streaming(file, budget, false);
    ASSERT_TRUE(streaming.streams());
    viewer::GpuScene held(file, *viewer_gl().programs, {}, streaming.visible(close_up(), 0));
    EXPECT_LE(bytes_of(held), budget);
    EXPECT_LT(held.fiber_count(), file.header().fibers);

    // Brute force: the fibers with a decoded point inside the frustum.
    const CpuDecoded decoded = cpu_decode_blocks(file);
    const Frustum frustum = frustum_from_camera(close_up());
    std::vector<std::uint32_t> seen;
    for (std::uint64_t f = 0; f < file.header().fibers; ++f) {
        const std::size_t b0 = file.first_block(f), b1 = b0 + file.block_count(f);
        for (std::size_t p = decoded.block_first[b0]; p < decoded.block_first[b1]; ++p)
            if (sphere_intersects_frustum(frustum, decoded.point(p), 0)) {
                seen.push_back(std::uint32_t(f));
                break;
            }
    }
    ASSERT_GT(seen.size(), 20u);
    EXPECT_EQ(held.scene_fibers(seen).size(), seen.size()) << "a fiber in view is not held";

    const DrawnFrame expected = draw(whole.scene), got = draw(held);
    EXPECT_GT(drawn_pixels(expected), std::size_t(kWidth * kHeight / 4));
    EXPECT_EQ(got.rgba, expected.rgba);
    EXPECT_EQ(got.file_fibers, expected.file_fibers);
}

// Thinned levels: a larger budget holds every fiber of a smaller one, and
// the overview (drawn while the view moves) is within every view's level.
TEST(ViewerStreaming, DenserLevelsHoldEverySparserOne) {
    FIBLET_REQUIRE_GL();
    const CompressedScene whole(parallel_fibers());
    const FftFile& file = whole.file;
    Camera wide = close_up();
    wide.position = {-2, 0, 120}, wide.target = {-2, 0, 0}, wide.far_mm = 300;
    std::vector<std::uint64_t> sparser;
    for (const double share : {0.3, 0.45, 0.6, 0.9}) {
        SCOPED_TRACE(share);
        const viewer::FiberStreaming streaming(file, share_of_file(file, share), false);
        ASSERT_TRUE(streaming.streams());
        viewer::FiberSubset level = streaming.visible(wide, 0);
        const viewer::GpuScene held(file, *viewer_gl().programs, {}, level);
        EXPECT_LE(bytes_of(held), streaming.budget_bytes());
        // Thinned to within a few fibers of the budget: at least half of it used.
        EXPECT_GE(bytes_of(held), streaming.budget_bytes() / 2);
        EXPECT_TRUE(std::includes(level.fibers.begin(), level.fibers.end(), sparser.begin(), sparser.end()));
        EXPECT_TRUE(std::includes(level.fibers.begin(), level.fibers.end(), streaming.overview().fibers.begin(),
                                  streaming.overview().fibers.end()));
        // (Small budgets leave the overview, a quarter of them, nothing
        // beside the direction frames every scene takes.)
        if (share >= 0.9) {
            EXPECT_FALSE(streaming.overview().fibers.empty());
        }
        sparser = level.fibers;
    }
}

// Picking and highlighting speak of the file's fibers in a held part too.
TEST(ViewerStreaming, PickingAndHighlightsUseTheFilesIndices) {
    FIBLET_REQUIRE_GL();
    const CompressedScene whole(parallel_fibers());
    const FftFile& file = whole.file;
    const viewer::FiberStreaming streaming(file, share_of_file(file, 0.6), false);
    const viewer::GpuScene held(file, *viewer_gl().programs, {}, streaming.visible(close_up(), 0));
    ASSERT_FALSE(held.holds_every_fiber());

    viewer::Renderer renderer(*viewer_gl().programs);
    viewer::RenderTarget target(kWidth, kHeight);
    renderer.render(whole.scene, close_up(), {}, target);
    const auto expected = viewer::pick_fiber(target, whole.scene, kWidth / 2, kHeight / 2, 3);
    renderer.render(held, close_up(), {}, target);
    const auto got = viewer::pick_fiber(target, held, kWidth / 2, kHeight / 2, 3);
    ASSERT_TRUE(expected && got);
    EXPECT_EQ(got->index, expected->index);
    EXPECT_EQ(got->id, expected->id);
    EXPECT_EQ(got->points, expected->points);
    EXPECT_GT(got->index, held.scene_fibers({std::uint32_t(got->index)}).front()) << "the scene's index, not the file's";

    viewer::RenderOptions o;
    o.highlighted_fibers = {std::uint32_t(expected->index)};
    EXPECT_EQ(draw(held, o).rgba, draw(whole.scene, o).rgba);
}

// Colours, radii and point values are given per file fiber and point; a held
// part, a part held again (reside) and a scene made from another's
// attributes draw what the whole file draws, with every technique's caches
// (voxel-rt) following the blocks held.
TEST(ViewerStreaming, AttributesAndCachesFollowTheHeldFibers) {
    FIBLET_REQUIRE_GL();
    CompressedScene whole(parallel_fibers());
    const FftFile& file = whole.file;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.2f, 1.0f);
    std::vector<std::array<float, 3>> colors(file.header().fibers);
    for (auto& c : colors) c = {u(rng), u(rng), u(rng)};
    std::vector<float> radii(file.header().fibers);
    for (float& r : radii) r = 0.05f + 0.1f * u(rng);
    std::vector<float> values;
    for (const std::uint32_t n : whole.scene.file_fiber_point_counts())
        for (std::uint32_t i = 0; i < n; ++i) values.push_back(float(i) / float(n) + u(rng));
    whole.scene.set_fiber_colors(colors);
    whole.scene.set_fiber_radii(radii);
    whole.scene.set_point_values(values);

    const viewer::FiberStreaming streaming(file, share_of_file(file, 0.5, true), true);
    ASSERT_TRUE(streaming.streams());
    Camera elsewhere = close_up();
    elsewhere.position.y = elsewhere.target.y = 12;
    viewer::GpuScene held(file, *viewer_gl().programs, {}, streaming.visible(elsewhere, 0.2f));
    held.set_fiber_colors(colors);
    held.set_fiber_radii(radii);
    held.set_point_values(values);

    viewer::RenderOptions by_fiber, by_point, voxel_rt;
    by_fiber.fiber_colors = true;
    by_point.point_values = true;
    voxel_rt.engine = viewer::RenderEngine::voxel_rt, voxel_rt.fiber_radii = true, voxel_rt.fiber_colors = true;
    // The held scene's renderer keeps its caches across reside(): the
    // voxel structure of the first part must not serve the second.
    viewer::Renderer renderer(*viewer_gl().programs), reference(*viewer_gl().programs);
    viewer::RenderTarget target(kWidth, kHeight);
    renderer.render(held, elsewhere, voxel_rt, target);
    held.reside(file, *viewer_gl().programs, streaming.visible(close_up(), 0.2f));
    const viewer::GpuScene copied(held, file, *viewer_gl().programs, streaming.visible(close_up(), 0.2f));
    for (const viewer::RenderOptions& o : {voxel_rt, by_fiber, by_point}) {
        SCOPED_TRACE(viewer::render_engine_name(o.engine));
        reference.render(whole.scene, close_up(), o, target);
        const std::vector<std::uint8_t> expected = target.read_rgba();
        EXPECT_GT(std::count(expected.begin(), expected.end(), 0), 0);
        renderer.render(held, close_up(), o, target);
        EXPECT_EQ(target.read_rgba(), expected);
        renderer.render(copied, close_up(), o, target);
        EXPECT_EQ(target.read_rgba(), expected);
    }
}

TEST(ViewerStreaming, RefusesASubsetThatIsNotAscendingFibersOfItsFile) {
    FIBLET_REQUIRE_GL();
    CompressedScene whole(parallel_fibers());
    auto index = std::make_shared<const BlockIndex>(BlockIndex::load(whole.file));
    for (const std::vector<std::uint64_t>& bad : {std::vector<std::uint64_t>{3, 2}, {5, 5}, {240}})
        EXPECT_THROW(whole.scene.reside(whole.file, *viewer_gl().programs, viewer::FiberSubset{bad, index}), Error);
    EXPECT_THROW(whole.scene.reside(whole.file, *viewer_gl().programs, viewer::FiberSubset{{1, 2}, nullptr}), Error);
}
