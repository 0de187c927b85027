// Camera and frustum: the geometric frustum planes agree with clipping by
// the projection matrix (an independent formulation), and LoD sizes match a
// projection of the sphere's edge.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fiblet/view.hpp"

using namespace fiblet;

namespace {
std::array<float, 4> mul(const Mat4& m, Vec3f p) {
    std::array<float, 4> r{};
    for (int row = 0; row < 4; ++row) r[row] = m[row] * p.x + m[4 + row] * p.y + m[8 + row] * p.z + m[12 + row];
    return r;
}
bool clip_inside(const Mat4& vp, Vec3f p) {
    const auto c = mul(vp, p);
    return c[3] > 0 && std::fabs(c[0]) <= c[3] && std::fabs(c[1]) <= c[3] && std::fabs(c[2]) <= c[3];
}
}  // namespace

TEST(View, FrustumPlanesAgreeWithProjectionClipping) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-150, 150);
    Camera cam;
    cam.position = {40, -120, 90};
    cam.target = {5, 3, -2};
    cam.up = {0, 0, 1};
    cam.fov_y_deg = 50, cam.aspect = 1.5f, cam.near_mm = 5, cam.far_mm = 400;
    const Frustum f = frustum_from_camera(cam);
    const Mat4 vp = view_projection_matrix(cam);
    int inside = 0, checked = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3f p{u(rng), u(rng), u(rng)};
        bool in_planes = true;
        float margin = 1e9f;
        for (const Plane& pl : f.planes) {
            const float s = pl.n.x * p.x + pl.n.y * p.y + pl.n.z * p.z + pl.d;
            in_planes &= s >= 0;
            margin = std::min(margin, std::fabs(s));
        }
        if (margin < 1e-2f) continue;  // too close to a plane for float comparison
        ++checked;
        inside += in_planes;
        EXPECT_EQ(in_planes, clip_inside(vp, p)) << p.x << " " << p.y << " " << p.z;
        EXPECT_EQ(in_planes, sphere_intersects_frustum(f, p, 0.0f));
    }
    EXPECT_GT(inside, 100);
    EXPECT_GT(checked - inside, 100);
}

TEST(View, ProjectedRadiusMatchesTheProjectionOfTheSphereEdge) {
    Camera cam;
    cam.position = {0, 0, 300};
    const Viewport vp{800, 600};
    const Vec3f c{0, 0, 0};
    const float r = 2;
    // Project the top of the sphere (at the same depth) through the matrix.
    const auto top = mul(view_projection_matrix(cam), {0, r, 0});
    const float pixels = top[1] / top[3] * 0.5f * vp.height;
    EXPECT_NEAR(projected_radius_px(cam, vp, c, r), pixels, 1e-3f);
    EXPECT_TRUE(block_is_coarse(cam, vp, c, 0.01f));
    EXPECT_FALSE(block_is_coarse(cam, vp, c, 20.0f));
    EXPECT_TRUE(std::isinf(projected_radius_px(cam, vp, {0, 0, 299}, 5)));
}
