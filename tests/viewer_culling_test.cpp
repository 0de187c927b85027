// GPU block selection (cull_blocks.comp.glsl) against the CPU definitions of
// fiblet/view.hpp: the same decision for every block up to float rounding at
// the boundaries, no block with a visible point ever culled, and the fiber
// subset and draw counters exact.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scene/gpu_scene.hpp"
#include "render/renderer.hpp"
#include "viewer_test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;
using viewer::BlockDecision;

namespace {

double norm(Vec3f v) { return std::sqrt(double(v.x) * v.x + double(v.y) * v.y + double(v.z) * v.z); }

struct Scene {
    FftFile file;
    viewer::GpuScene gpu;
    std::vector<std::uint8_t> blocks;
    CpuDecoded decoded;
    std::vector<bool> last_of_fiber;  // from the LUT
    explicit Scene(const std::string& path)
        : file(path),
          gpu(file, *viewer_gl().programs),
          blocks(file.read_blocks(0, file.header().blocks)),
          decoded(cpu_decode_blocks(file)),
          last_of_fiber(file.header().blocks, false) {
        for (std::uint64_t f = 0; f < file.header().fibers; ++f)
            if (file.block_count(f)) last_of_fiber[file.first_block(f) + file.block_count(f) - 1] = true;
    }
    const std::uint8_t* block(std::uint32_t b) const { return &blocks[std::size_t(b) * file.header().block_bytes()]; }
};

Camera make_camera(Vec3f eye, Vec3f target, float fov, float aspect, float near_mm, float far_mm) {
    Camera c;
    c.position = eye, c.target = target, c.up = {0, 0, 1};
    c.fov_y_deg = fov, c.aspect = aspect, c.near_mm = near_mm, c.far_mm = far_mm;
    return c;
}

// Runs the GPU selection and checks every block against view.hpp.
struct Tally {
    std::size_t outside = 0, coarse = 0, fine = 0, borderline = 0;
};
Tally check_camera(const Scene& s, viewer::Renderer& renderer, const Camera& cam, const Viewport& vp, bool lod) {
    viewer::RenderOptions o;
    o.frustum_culling = true, o.level_of_detail = lod, o.record_decisions = true;
    const viewer::DrawCounters counters = renderer.select_blocks(s.gpu, cam, vp, o);
    const std::vector<BlockDecision> gpu = renderer.read_decisions(s.gpu);
    const FftHeader& h = s.file.header();
    const Frustum frustum = frustum_from_camera(cam);

    Tally t;
    std::uint64_t fine_blocks = 0, coarse_blocks = 0, fine_segments = 0, coarse_segments = 0;
    for (std::uint32_t b = 0; b < h.blocks; ++b) {
        const Sphere sphere = block_bounding_sphere(h, s.block(b));
        const bool inside = sphere_intersects_frustum(frustum, sphere.center, sphere.radius);
        const bool coarse = lod && block_is_coarse(cam, vp, sphere.center, sphere.radius, o.lod_pixels);
        const BlockDecision want =
            !inside ? BlockDecision::outside_frustum : coarse ? BlockDecision::coarse : BlockDecision::fine;
        if (gpu[b] != want) {
            // Only float rounding at a boundary may tell them apart.
            double margin = 1e30;
            for (const Plane& p : frustum.planes)
                margin = std::min(margin, std::fabs(double(p.n.x) * sphere.center.x + double(p.n.y) * sphere.center.y +
                                                    double(p.n.z) * sphere.center.z + p.d + sphere.radius));
            const bool frustum_edge = margin <= 4e-6 * (norm(sphere.center) + norm(cam.position) + sphere.radius);
            const double px = 2.0 * projected_radius_px(cam, vp, sphere.center, sphere.radius);
            const bool lod_edge = std::fabs(px - o.lod_pixels) <= 1e-4 * o.lod_pixels;
            EXPECT_TRUE(frustum_edge || lod_edge)
                << "block " << b << ": GPU " << unsigned(gpu[b]) << ", view.hpp " << unsigned(want);
            ++t.borderline;
        }
        // No block with a point inside the frustum is culled (the sphere
        // contains the decoded points; margin against float rounding).
        if (gpu[b] == BlockDecision::outside_frustum) {
            for (std::size_t i = s.decoded.block_first[b]; i < s.decoded.block_first[b + 1]; ++i) {
                const Vec3f p = s.decoded.point(i);
                bool strictly_inside = true;
                for (const Plane& pl : frustum.planes)
                    strictly_inside &= double(pl.n.x) * p.x + double(pl.n.y) * p.y + double(pl.n.z) * p.z + pl.d > 1e-4;
                EXPECT_FALSE(strictly_inside) << "block " << b << " culled, its point " << i << " is visible";
                if (strictly_inside) break;
            }
        }
        // The draw counters: segments of a block in full (its own plus the
        // one to the next block of its fiber), or one for a coarse block.
        const bool last = s.last_of_fiber[b];
        const std::uint32_t n = BlockView{s.block(b)}.point_count();
        if (gpu[b] == BlockDecision::fine) {
            ++t.fine;
            const std::uint32_t segs = n - 1 + (last ? 0 : 1);
            fine_blocks += segs > 0, fine_segments += segs;
        } else if (gpu[b] == BlockDecision::coarse) {
            ++t.coarse;
            const std::uint32_t segs = last && n < 2 ? 0 : 1;
            coarse_blocks += segs, coarse_segments += segs;
        } else {
            ++t.outside;
        }
    }
    EXPECT_EQ(counters.fine_blocks, fine_blocks);
    EXPECT_EQ(counters.coarse_blocks, coarse_blocks);
    EXPECT_EQ(counters.fine_segments, fine_segments);
    EXPECT_EQ(counters.coarse_segments, coarse_segments);
    return t;
}

}  // namespace

TEST(ViewerCulling, GpuDecisionsAreThoseOfViewHpp) {
    FIBLET_REQUIRE_GL();
    const Scene s(shared_data("reference/small-sdstream.fft"));
    viewer::Renderer renderer(*viewer_gl().programs);
    // The data spans about +-40 mm around the origin.
    struct Case {
        Camera camera;
        Viewport viewport;
        const char* what;
    };
    std::vector<Case> cases = {
        {make_camera({150, 100, 60}, {0, 0, 0}, 35, 16.0f / 9, 1, 1000), {1920, 1080}, "whole brain"},
        {make_camera({0, -20, 10}, {30, 10, 10}, 60, 1.0f, 0.5f, 500), {800, 800}, "inside, looking sideways"},
        {make_camera({60, 0, 0}, {0, 0, 0}, 20, 4.0f / 3, 10, 1000), {640, 480}, "close-up"},
        {make_camera({2000, 1500, 800}, {0, 0, 0}, 35, 16.0f / 9, 100, 5000), {1920, 1080}, "far: level of detail"},
        {make_camera({150, 100, 60}, {0, 0, 0}, 35, 1.0f, 150, 190), {256, 256}, "near and far planes cut it"},
    };
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1, 1);
    for (int i = 0; i < 12; ++i) {
        const float d = 20 + 400 * (u(rng) + 1);
        Vec3f eye{u(rng), u(rng), u(rng)};
        const float n = float(norm(eye));
        eye = {eye.x / n * d, eye.y / n * d, eye.z / n * d};
        cases.push_back({make_camera(eye, {20 * u(rng), 20 * u(rng), 20 * u(rng)}, 50 + 40 * u(rng), 1 + 0.8f * u(rng),
                                     0.5f + 0.4f * u(rng), 2000),
                         {int(600 + 500 * u(rng)), int(600 + 500 * u(rng))},
                         "random"});
    }
    Tally total;
    for (const Case& c : cases) {
        for (bool lod : {false, true}) {
            SCOPED_TRACE(std::string(c.what) + (lod ? ", LoD" : ""));
            const Tally t = check_camera(s, renderer, c.camera, c.viewport, lod);
            total.outside += t.outside, total.coarse += t.coarse, total.fine += t.fine;
            total.borderline += t.borderline;
        }
    }
    // The cases exercise every decision, and boundary ties stay rare.
    EXPECT_GT(total.outside, 10000u);
    EXPECT_GT(total.coarse, 10000u);
    EXPECT_GT(total.fine, 10000u);
    EXPECT_LT(total.borderline, 10u);
    std::printf("blocks: %zu culled, %zu coarse, %zu fine, %zu on a boundary\n", total.outside, total.coarse,
                total.fine, total.borderline);
}

TEST(ViewerCulling, FiberSubsetByIdAndLength) {
    FIBLET_REQUIRE_GL();
    const Scene s(shared_data("reference/small-sdstream.fft"));
    viewer::Renderer renderer(*viewer_gl().programs);
    const FftHeader& h = s.file.header();
    const double step_mm = double(h.step) * h.scaling;
    viewer::RenderOptions o;
    o.frustum_culling = o.level_of_detail = false;
    o.record_decisions = true;
    o.id_min = 100, o.id_max = 599;
    o.min_length_mm = 60, o.max_length_mm = 110;
    const Camera cam = make_camera({150, 100, 60}, {0, 0, 0}, 35, 1, 1, 1000);
    const viewer::DrawCounters c = renderer.select_blocks(s.gpu, cam, {256, 256}, o);
    const std::vector<BlockDecision> gpu = renderer.read_decisions(s.gpu);
    std::uint64_t selected = 0;
    for (std::uint64_t f = 0; f < h.fibers; ++f) {
        const std::uint32_t id = s.gpu.fiber_id(f);
        const double length = double(s.gpu.fiber_points(f) - 1) * step_mm;
        const bool in = id >= o.id_min && id <= o.id_max && length >= o.min_length_mm && length <= o.max_length_mm;
        for (std::uint64_t b = s.file.first_block(f); b < s.file.first_block(f) + s.file.block_count(f); ++b) {
            EXPECT_EQ(gpu[b], in ? BlockDecision::fine : BlockDecision::not_selected) << "fiber " << f;
            // Listed when it has a segment to draw (a lone last point has none).
            selected += in && !(s.last_of_fiber[b] && BlockView{s.block(std::uint32_t(b))}.point_count() < 2);
        }
    }
    EXPECT_EQ(c.fine_blocks, selected);
    EXPECT_GT(selected, 0u);
    EXPECT_LT(selected, h.blocks / 2);
}
