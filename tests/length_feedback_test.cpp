// The length feedback's measuring helpers (encode/length_feedback.hpp):
// max_distance2's vector loop against its scalar loop bit for bit and
// against a brute force in double; add_step_errors against the running
// sum it replaces.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "encode/length_feedback.hpp"
#include "scoped_simd_loops.hpp"

using namespace fiblet;
using detail::add_step_errors;
using detail::max_distance2;
using detail::operator-;

namespace {

std::vector<Vec3f> random_points(std::size_t n, float scale, std::mt19937& rng) {
    std::uniform_real_distribution<float> u(-scale, scale);
    std::vector<Vec3f> p(n);
    for (Vec3f& v : p) v = {u(rng), u(rng), u(rng)};
    return p;
}

// The scalar loop (the AVX2 loops switched off for this thread).
float scalar_max_distance2(const Vec3f* a, const Vec3f* b, std::size_t m) {
    return test::with_simd_loops(false, false, [&] { return max_distance2(a, b, m); });
}

}  // namespace

TEST(LengthFeedback, MaxDistanceIsTheLargestSquaredDistanceAtAnyLength) {
    std::mt19937 rng(7);
    for (std::size_t m : {0, 1, 7, 8, 9, 15, 16, 17, 58, 60, 61, 254}) {
        for (int trial = 0; trial < 20; ++trial) {
            std::vector<Vec3f> a = random_points(m, 100.0f, rng), b = random_points(m, 100.0f, rng);
            // The largest distance in every position of an 8-point group, and at the tail.
            if (m > 0) {
                const std::size_t at = std::size_t(trial) % m;
                a[at] = {1e3f, -1e3f, 5e2f};
            }
            double brute = 0;  // of the float differences, as the loops square them
            for (std::size_t k = 0; k < m; ++k) {
                const double dx = a[k].x - b[k].x, dy = a[k].y - b[k].y, dz = a[k].z - b[k].z;
                brute = std::max(brute, dx * dx + dy * dy + dz * dz);
            }
            const float vector = max_distance2(a.data(), b.data(), m);
            EXPECT_EQ(vector, scalar_max_distance2(a.data(), b.data(), m)) << m << " " << trial;
            EXPECT_NEAR(vector, brute, 1e-6 * brute) << m << " " << trial;
        }
    }
}

TEST(LengthFeedback, MaxDistanceOfEqualPointsIsZero) {
    std::mt19937 rng(11);
    const std::vector<Vec3f> a = random_points(61, 1.0f, rng);
    EXPECT_EQ(max_distance2(a.data(), a.data(), a.size()), 0.0f);
}

// The same bits with the AVX2 terms (where the CPU has them) and without,
// and as the running sum in order: add_step_errors sums the float terms in
// four running double sums, which is exact for terms of these magnitudes.
TEST(LengthFeedback, StepErrorsEqualTheRunningSum) {
    std::mt19937 rng(3);
    for (std::size_t n : {2, 3, 9, 10, 17, 64, 65, 66, 129, 300}) {
        const std::vector<Vec3f> points = random_points(n, 2.0f, rng), targets = random_points(n, 2.0f, rng);
        for (std::size_t from : {std::size_t(1), std::size_t(2), n / 2}) {
            if (from < 1 || from > n) continue;
            double running = 0.25;
            for (std::size_t k = from; k < n; ++k)
                running += detail::norm(points[k] - points[k - 1]) - detail::norm(targets[k] - targets[k - 1]);
            for (const bool avx2 : {true, false}) {
                const test::ScopedSimdLoops loops(avx2);
                EXPECT_EQ(add_step_errors(0.25, points.data(), targets.data(), from, n), running)
                    << n << " " << from << " avx2 " << avx2;
            }
        }
    }
}
