// The 16-bit direction code: codes decode to unit vectors, re-encode to
// themselves, and nearest_code finds the true nearest of all 65536 codes,
// also for directions a hair off the axis (where 1 - x^2 cancels in float:
// the inverse cap map once sent such directions to codes 7 degrees away).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fiblet/direction_code.hpp"

using namespace fiblet;

namespace {
double dotd(Vec3f a, Vec3f b) { return double(a.x) * b.x + double(a.y) * b.y + double(a.z) * b.z; }
}  // namespace

TEST(DirectionCode16, CodesAreUnitAndReencodeToThemselves) {
    for (unsigned k = 0; k < 65536; k += 7) {
        const Vec3f v = dequantize_half_octahedron16(std::uint16_t(k));
        EXPECT_NEAR(std::sqrt(dotd(v, v)), 1.0, 1e-6);
        EXPECT_EQ(quantize_half_octahedron16(v), k);
    }
}

TEST(DirectionCode16, NearestCodeIsTheTrueNearestEvenNearTheAxis) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0, 1);
    for (float ratio : {0.0068f, 0.1676f, 0.6f}) {
        const DirectionTable16 t(ratio);
        const double cap = std::acos(1.0 - ratio);
        for (int i = 0; i < 120; ++i) {
            // Polar angles from 1e-5 rad to the cap, log-spaced.
            const double polar = cap * std::pow(1e-5 / cap, u(rng)), az = 2 * M_PI * u(rng);
            const Vec3f d{float(std::cos(polar)), float(std::sin(polar) * std::cos(az)), float(std::sin(polar) * std::sin(az))};
            double best = -2;
            for (unsigned c = 0; c < 65536; ++c) best = std::max(best, dotd(t.direction(std::uint16_t(c)), d));
            const double got = dotd(t.direction(t.nearest_code(d)), d);
            // nearest_code compares float dot products: the nearest up to their
            // rounding (a few 1e-8; neighbouring codes differ by 1e-7 and more).
            EXPECT_GE(got, best - 3e-7) << "ratio " << ratio << " polar " << polar;
        }
    }
}

TEST(DirectionCode16, DirectionsAHairOffTheAxisGetACentralCode) {
    // Unit vectors within 2.4e-4 rad of the axis have x == 1.0f exactly; the
    // nearest code is one of the central ones (levels 124..131), for any ratio.
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(0, 1);
    for (int r = 0; r < 40; ++r) {
        const float ratio = float(0.005 + 0.5 * u(rng));
        const DirectionTable16 t(ratio);
        for (int i = 0; i < 50; ++i) {
            const double polar = 2.4e-4 * u(rng), az = 2 * M_PI * u(rng);
            const double len = 1e-4 + u(rng);  // nearest_code takes any length
            const Vec3f d{float(len), float(len * polar * std::cos(az)), float(len * polar * std::sin(az))};
            double best = -2;
            for (unsigned h = 124; h <= 131; ++h)
                for (unsigned l = 124; l <= 131; ++l) best = std::max(best, dotd(t.direction(std::uint16_t(h << 8 | l)), d));
            EXPECT_GE(dotd(t.direction(t.nearest_code(d)), d), best - 3e-7 * len) << "ratio " << ratio;
        }
    }
}
