// The 8-bit direction code: every code is a unit vector, codes are stable
// under re-encoding, and the angular error stays inside the cell bound.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fiblet/direction_code.hpp"

using namespace fiblet;

namespace {
double dotd(Vec3f a, Vec3f b) { return double(a.x) * b.x + double(a.y) * b.y + double(a.z) * b.z; }
double normd(Vec3f a) { return std::sqrt(dotd(a, a)); }
Vec3f unit(double x, double y, double z) {
    const double n = std::sqrt(x * x + y * y + z * z);
    return {float(x / n), float(y / n), float(z / n)};
}
// Angle (radians) from `d` to the closest of the 256 cap directions, by brute force.
double nearest_angle(const DirectionTable& t, Vec3f d) {
    double best = -2;
    for (int k = 0; k < 256; ++k) best = std::max(best, dotd(t.direction(std::uint8_t(k)), d));
    return std::acos(std::min(best, 1.0));
}
}  // namespace

TEST(DirectionCode, EveryCodeDecodesToAUnitVectorOnTheHalfSphere) {
    for (int k = 0; k < 256; ++k) {
        const Vec3f v = dequantize_half_octahedron(std::uint8_t(k));
        EXPECT_NEAR(normd(v), 1.0, 1e-6) << k;
        EXPECT_GE(v.x, -1e-6f) << k;  // rim codes: x = 1 - |y| - |z| = 0 up to rounding
    }
}

TEST(DirectionCode, ReencodingADecodedDirectionGivesTheSameCode) {
    for (int k = 0; k < 256; ++k)
        EXPECT_EQ(quantize_half_octahedron(dequantize_half_octahedron(std::uint8_t(k))), k) << k;
    for (float ratio : {0.05f, 0.1458f, 0.5f, 1.0f, 1.7f}) {
        const DirectionTable t(ratio);
        for (int k = 0; k < 256; ++k) {
            const Vec3f d = t.direction(std::uint8_t(k));
            EXPECT_NEAR(normd(d), 1.0, 1e-6);
            EXPECT_EQ(t.nearest_code(d), k) << "ratio " << ratio << " code " << k;
        }
    }
}

TEST(DirectionCode, CapMappingRoundTripsAndStaysInTheCap) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    for (float ratio : {0.1f, 0.5f, 1.0f, 1.9f}) {
        for (int i = 0; i < 2000; ++i) {
            Vec3f h = unit(std::fabs(u(rng)), u(rng), u(rng));
            const Vec3f c = map_half_sphere_to_cap(h, ratio);
            EXPECT_NEAR(normd(c), 1.0, 1e-5);
            EXPECT_GE(c.x, 1.0f - ratio - 1e-6f);
            const Vec3f back = map_cap_to_half_sphere(c, ratio);
            EXPECT_NEAR(back.x, h.x, 2e-4);
            EXPECT_NEAR(back.y, h.y, 2e-3);
            EXPECT_NEAR(back.z, h.z, 2e-3);
        }
    }
}

TEST(DirectionCode, NearestCodeIsTheTrueNearestAndWithinTheCellBound) {
    // The bound: the half-octahedron grid has spacing 2/15 on each diagonal
    // axis, so any point of the diamond is within (1/15)*sqrt(2) (L2, in the
    // (vy, vz) plane) of a grid point; the gnomonic-like projection to the
    // sphere stretches distances by at most sqrt(2)*... — rather than a loose
    // closed form, we check the encoder against brute force over all codes,
    // and that the worst case seen is below the cell's circumradius mapped by
    // the cap, measured on a dense sample.
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    for (float ratio : {0.1458f, 0.6f}) {
        const DirectionTable t(ratio);
        // Circumradius bound of a cell on the half sphere: adjacent codes are
        // at most this far apart in angle; a direction is within half the
        // largest neighbour distance times sqrt(2) of its nearest code.
        double max_neighbour = 0;
        for (int h = 0; h < 16; ++h)
            for (int l = 0; l < 16; ++l)
                for (auto [dh, dl] : {std::pair{1, 0}, std::pair{0, 1}}) {
                    if (h + dh > 15 || l + dl > 15) continue;
                    const double c = dotd(t.direction(std::uint8_t(h << 4 | l)),
                                          t.direction(std::uint8_t((h + dh) << 4 | (l + dl))));
                    max_neighbour = std::max(max_neighbour, std::acos(std::min(c, 1.0)));
                }
        const double bound = max_neighbour * std::sqrt(2.0) / 2 * 1.0001;
        for (int i = 0; i < 5000; ++i) {
            // Uniform directions inside the cap.
            const double cx = 1.0 - ratio * (u(rng) * 0.5 + 0.5);
            const double phi = M_PI * u(rng);
            const double s = std::sqrt(std::max(0.0, 1 - cx * cx));
            const Vec3f d = unit(cx, s * std::cos(phi), s * std::sin(phi));
            const std::uint8_t code = t.nearest_code(d);
            const double got = std::acos(std::min(dotd(t.direction(code), d), 1.0));
            EXPECT_NEAR(got, nearest_angle(t, d), 1e-6) << "not the nearest code";
            EXPECT_LE(got, bound);
        }
    }
}

TEST(DirectionCode, FramesAreOrthonormalEvenAlongTheHelperVector) {
    const Vec3f c{kFrameHelper[0], kFrameHelper[1], kFrameHelper[2]};
    for (Vec3f axis : {unit(1, 0, 0), unit(0, 0, 1), c, Vec3f{-c.x, -c.y, -c.z}, unit(c.x + 1e-5, c.y, c.z)}) {
        const Frame f = frame_from_axis(axis);
        for (int i = 0; i < 3; ++i) {
            EXPECT_NEAR(normd(f.c[i]), 1.0, 1e-5);
            for (int j = i + 1; j < 3; ++j) EXPECT_NEAR(dotd(f.c[i], f.c[j]), 0.0, 1e-5);
        }
        EXPECT_EQ(f.c[0], axis);
    }
}
