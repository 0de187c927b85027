// The capsules style against Intel Embree's round linear curves (a sphere
// swept along each segment: the same capsules; tests/embree_capsules.hpp),
// traced per pixel on the CPU through a real bundle. Embree is a test-only
// dependency; without it the test skips.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scene/gpu_scene.hpp"
#include "window/orbit_camera.hpp"
#include "render/render_target.hpp"
#include "render/renderer.hpp"
#include "viewer_test_util.hpp"

#if FIBLET_HAS_EMBREE
#include "embree_capsules.hpp"
#endif

using namespace fiblet;
using namespace fiblet::test;

#if FIBLET_HAS_EMBREE
namespace {

// Per pixel of the camera's w × h image, Embree's hit distance along the
// pixel's unit ray (+inf: miss).
std::vector<float> embree_image(const FftFile& file, float radius, const Camera& cam, int w, int h) {
    const EmbreeCapsules oracle(file, radius);
    std::vector<float> out(std::size_t(w) * std::size_t(h), INFINITY);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            out[std::size_t(y) * std::size_t(w) + std::size_t(x)] = oracle.nearest(cam.position, camera_pixel_ray(cam, x, y, w, h)).t;
    return out;
}

}  // namespace
#endif

TEST(ViewerCapsules, AgreeWithEmbreeOnARealBundle) {
#if !FIBLET_HAS_EMBREE
    GTEST_SKIP() << "built without Embree (libembree-dev, scripts/setup.sh)";
#else
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(shared_data("bundles/CST_R-step0.1.tck"));
    const FftFile& file = compressed.file;
    const viewer::GpuScene& scene = compressed.scene;
    const int w = 200, h = 200;
    const float radius = 0.3f;
    for (const char* view : {"left", "oblique"}) {
        SCOPED_TRACE(view);
        const Camera cam = viewer::camera_from_spec(view, scene, 1.0f, 35, 2.0f);
        viewer::Renderer renderer(*viewer_gl().programs);
        viewer::RenderTarget target(w, h);
        viewer::RenderOptions o;
        o.style = viewer::DrawStyle::capsules;
        o.tube_radius_mm = radius;
        o.level_of_detail = false;
        renderer.render(scene, cam, o, target);
        const auto fibers = target.read_fibers();
        const auto depth = target.read_depth();
        const auto ref = embree_image(file, radius, cam, w, h);
        auto hit = [&](int x, int y) { return std::isfinite(ref[std::size_t(y) * std::size_t(w) + std::size_t(x)]); };
        std::size_t compared = 0, agree = 0, hits = 0, depth_ok = 0, both = 0;
        // Depths compared as eye depth: the GPU's window depth unprojected,
        // Embree's distance along the unit pixel ray times the ray's cosine
        // with the view axis.
        const double n = cam.near_mm, f = cam.far_mm;
        for (int y = 1; y + 1 < h; ++y)
            for (int x = 1; x + 1 < w; ++x) {
                bool band = false;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) band |= hit(x + dx, y + dy) != hit(x, y);
                if (band) continue;
                ++compared;
                hits += hit(x, y);
                const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
                agree += hit(x, y) == (fibers[i] != 0);
                if (!hit(x, y) || fibers[i] == 0) continue;
                ++both;
                const double z_gpu = 2 * n * f / ((f + n) - (2.0 * depth[i] - 1.0) * (f - n));
                const double tt = std::tan(double(cam.fov_y_deg) * M_PI / 360.0);
                const double nx = (x + 0.5) / w * 2 - 1, ny = 1 - (y + 0.5) / h * 2;
                const double cosine = 1.0 / std::sqrt(1 + nx * nx * tt * tt * cam.aspect * cam.aspect + ny * ny * tt * tt);
                depth_ok += std::fabs(double(ref[i]) * cosine - z_gpu) <= 0.01 * radius;
            }
        const double rate = double(agree) / double(compared);
        const double depth_rate = double(depth_ok) / double(both);
        std::printf("%s: capsules vs Embree, %zu pixels outside the silhouette band (%zu hit): hit/miss %.5f, "
                    "distance within 0.01 r %.5f\n",
                    view, compared, hits, rate, depth_rate);
        EXPECT_GT(hits, 2000u);
        EXPECT_GE(rate, 0.999);
        EXPECT_GE(depth_rate, 0.99);
    }
#endif
}
