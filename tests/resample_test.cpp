// Fixed-step resampling: every chord equals the step, every point lies on the
// original polyline, and the dropped tail is shorter than one step.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fiblet/resample.hpp"

using namespace fiblet;

namespace {
double dist(Vec3f a, Vec3f b) { return std::hypot(double(a.x) - b.x, double(a.y) - b.y, double(a.z) - b.z); }
}  // namespace

TEST(Resample, ChordsEqualTheStepAndPointsLieOnThePolyline) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1, 1), len(0.05f, 0.9f);
    for (int trial = 0; trial < 50; ++trial) {
        // A random-walk polyline with irregular spacing (some tiny segments).
        std::vector<Vec3f> line{{0, 0, 0}};
        for (int i = 0; i < 200; ++i) {
            Vec3f d{u(rng), u(rng), u(rng)};
            const float n = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
            const float l = i % 17 == 0 ? 1e-4f : len(rng);
            line.push_back({line.back().x + d.x / n * l, line.back().y + d.y / n * l, line.back().z + d.z / n * l});
        }
        const double step = 0.3;
        std::vector<Vec3f> out;
        resample_fixed_step(line, step, out);
        ASSERT_GE(out.size(), 2u);
        EXPECT_EQ(out.front(), line.front());
        for (std::size_t i = 1; i < out.size(); ++i) EXPECT_NEAR(dist(out[i - 1], out[i]), step, 1e-5);
        for (const Vec3f& p : out) EXPECT_LT(distance_to_polyline(p, line), 1e-5);
        // Nothing beyond the last point is farther than one step from it.
        // (The walk stops only when the rest of the polyline stays inside the
        // sphere of radius `step` around the last point.)
        double farthest = 0;
        std::size_t hint = 0;
        distance_to_polyline_near(out.back(), line, hint, line.size());
        for (std::size_t k = hint + 1; k < line.size(); ++k) farthest = std::max(farthest, dist(out.back(), line[k]));
        EXPECT_LT(farthest, step + 1e-6);
    }
}

TEST(Resample, ShortAndDegenerateInputs) {
    std::vector<Vec3f> out;
    resample_fixed_step({}, 1.0, out);
    EXPECT_TRUE(out.empty());
    const std::vector<Vec3f> one{{1, 2, 3}};
    resample_fixed_step(one, 1.0, out);
    EXPECT_EQ(out, one);
    const std::vector<Vec3f> same(10, Vec3f{1, 1, 1});  // zero-length segments
    resample_fixed_step(same, 0.5, out);
    EXPECT_EQ(out.size(), 1u);
    const std::vector<Vec3f> straight{{0, 0, 0}, {10, 0, 0}};
    resample_fixed_step(straight, 1.0, out);
    ASSERT_EQ(out.size(), 11u);
    for (std::size_t i = 0; i < out.size(); ++i) EXPECT_NEAR(out[i].x, float(i), 1e-5f);
}

TEST(Resample, WindowedDistanceMatchesBruteForceAlongThePolyline) {
    std::vector<Vec3f> line;
    for (int i = 0; i < 500; ++i) line.push_back({float(i) * 0.1f, std::sin(i * 0.05f), std::cos(i * 0.03f)});
    std::vector<Vec3f> out;
    resample_fixed_step(line, 0.37, out);
    std::size_t hint = 0;
    for (const Vec3f& p : out) {
        const Vec3f q{p.x + 0.01f, p.y - 0.02f, p.z};
        EXPECT_NEAR(distance_to_polyline_near(q, line, hint, 16), distance_to_polyline(q, line), 1e-9);
    }
}
