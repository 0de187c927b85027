// The capsules style against Intel Embree's round linear curves (a sphere
// swept along each segment: the same capsules), traced per pixel on the CPU
// through a real bundle. Embree is a test-only dependency; without it the
// test skips.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "gpu_scene.hpp"
#include "orbit_camera.hpp"
#include "render_target.hpp"
#include "renderer.hpp"
#include "viewer_test_util.hpp"

#if FIBLET_HAS_EMBREE
#include <embree3/rtcore.h>
#endif

using namespace fiblet;
using namespace fiblet::test;

#if FIBLET_HAS_EMBREE
namespace {

// Every fiber of the file (CPU-decoded points) as one round linear curve of
// constant radius; returns, per pixel of the camera's w × h image, the hit
// distance along the pixel's unit ray (+inf: miss).
std::vector<float> embree_image(const FftFile& file, float radius, const Camera& cam, int w, int h) {
    const CpuDecoded d = cpu_decode_blocks(file);
    RTCDevice device = rtcNewDevice(nullptr);
    RTCScene scene = rtcNewScene(device);
    RTCGeometry curves = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
    const std::size_t points = d.xyz.size() / 3;
    auto* v = static_cast<float*>(
        rtcSetNewGeometryBuffer(curves, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 16, points));
    for (std::size_t i = 0; i < points; ++i) {
        const Vec3f p = d.point(i);
        v[4 * i] = p.x, v[4 * i + 1] = p.y, v[4 * i + 2] = p.z, v[4 * i + 3] = radius;
    }
    std::vector<unsigned> starts;  // segment i joins points i and i + 1 of one fiber
    for (std::uint64_t f = 0; f < file.header().fibers; ++f) {
        const std::uint64_t first = file.first_block(f), count = file.block_count(f);
        for (std::size_t i = d.block_first[first]; i + 1 < d.block_first[first + count]; ++i) starts.push_back(unsigned(i));
    }
    auto* idx = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(curves, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, 4, starts.size()));
    std::copy(starts.begin(), starts.end(), idx);
    rtcCommitGeometry(curves);
    rtcAttachGeometry(scene, curves);
    rtcReleaseGeometry(curves);
    rtcCommitScene(scene);

    // The pixel rays of view.hpp's camera (as the oracle of viewer_tubes_test).
    auto unit = [](double x, double y, double z) {
        const double n = std::sqrt(x * x + y * y + z * z);
        return std::array<double, 3>{x / n, y / n, z / n};
    };
    const auto fwd = unit(cam.target.x - cam.position.x, cam.target.y - cam.position.y, cam.target.z - cam.position.z);
    const auto right = unit(fwd[1] * cam.up.z - fwd[2] * cam.up.y, fwd[2] * cam.up.x - fwd[0] * cam.up.z,
                            fwd[0] * cam.up.y - fwd[1] * cam.up.x);
    const std::array<double, 3> up{right[1] * fwd[2] - right[2] * fwd[1], right[2] * fwd[0] - right[0] * fwd[2],
                                   right[0] * fwd[1] - right[1] * fwd[0]};
    const double t = std::tan(double(cam.fov_y_deg) * M_PI / 360.0);
    std::vector<float> out(std::size_t(w) * std::size_t(h), INFINITY);
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double nx = (x + 0.5) / w * 2 - 1, ny = 1 - (y + 0.5) / h * 2;
            const auto dir = unit(fwd[0] + nx * t * cam.aspect * right[0] + ny * t * up[0],
                                  fwd[1] + nx * t * cam.aspect * right[1] + ny * t * up[1],
                                  fwd[2] + nx * t * cam.aspect * right[2] + ny * t * up[2]);
            RTCRayHit rh{};
            rh.ray.org_x = cam.position.x, rh.ray.org_y = cam.position.y, rh.ray.org_z = cam.position.z;
            rh.ray.dir_x = float(dir[0]), rh.ray.dir_y = float(dir[1]), rh.ray.dir_z = float(dir[2]);
            rh.ray.tnear = 0, rh.ray.tfar = INFINITY, rh.ray.mask = ~0u;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(scene, &context, &rh);
            if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) out[std::size_t(y) * std::size_t(w) + std::size_t(x)] = rh.ray.tfar;
        }
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
    return out;
}

}  // namespace
#endif

TEST(ViewerCapsules, AgreeWithEmbreeOnARealBundle) {
#if !FIBLET_HAS_EMBREE
    GTEST_SKIP() << "built without Embree (libembree-dev, scripts/setup.sh)";
#else
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const FftFile file(compress_into(dir, shared_data("bundles/CST_R-step0.1.tck"), "cst.fft"));
    const viewer::GpuScene scene(file, *viewer_gl().programs);
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
