// Fixed-step resampling: every chord equals the step, the dropped tail is
// shorter than one step; on the polyline curve every point lies on the input
// polyline, on the cubic every point lies on a smooth curve through the input
// points, and a smooth curve keeps its length whatever its sampling.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "fiblet/resample.hpp"

using namespace fiblet;

namespace {
double dist(Vec3f a, Vec3f b) { return std::hypot(double(a.x) - b.x, double(a.y) - b.y, double(a.z) - b.z); }
}  // namespace

// A random-walk polyline with irregular spacing (some tiny segments).
static std::vector<Vec3f> random_walk(std::mt19937& rng, int segments) {
    std::uniform_real_distribution<float> u(-1, 1), len(0.05f, 0.9f);
    std::vector<Vec3f> line{{0, 0, 0}};
    for (int i = 0; i < segments; ++i) {
        Vec3f d{u(rng), u(rng), u(rng)};
        const float n = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        const float l = i % 17 == 0 ? 1e-4f : len(rng);
        line.push_back({line.back().x + d.x / n * l, line.back().y + d.y / n * l, line.back().z + d.z / n * l});
    }
    return line;
}

static double length_of(const std::vector<Vec3f>& line) {
    double l = 0;
    for (std::size_t i = 1; i < line.size(); ++i) l += dist(line[i - 1], line[i]);
    return l;
}

TEST(Resample, ChordsEqualTheStepAndPointsLieOnThePolyline) {
    std::mt19937 rng(5);
    for (int trial = 0; trial < 50; ++trial) {
        const std::vector<Vec3f> line = random_walk(rng, 200);
        const double step = 0.3;
        std::vector<Vec3f> out;
        resample_fixed_step(line, step, out, ResampleCurve::polyline);
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

TEST(Resample, CubicChordsEqualTheStepAndStayNearThePolyline) {
    std::mt19937 rng(6);
    for (int trial = 0; trial < 50; ++trial) {
        const std::vector<Vec3f> line = random_walk(rng, 200);
        const double step = 0.3;
        std::vector<Vec3f> out;
        resample_fixed_step(line, step, out, ResampleCurve::cubic);
        ASSERT_GE(out.size(), 2u);
        EXPECT_EQ(out.front(), line.front());
        for (std::size_t i = 1; i < out.size(); ++i) EXPECT_NEAR(dist(out[i - 1], out[i]), step, 1e-5);
        // A Hermite segment with tangents of at most unit speed strays from
        // its chord by at most (4/27 + 4/27) of the chord's length: 0.27 mm
        // for these segments of up to 0.9 mm, even on this random walk's
        // sharp turns.
        for (const Vec3f& p : out) EXPECT_LT(distance_to_polyline(p, line), 0.3 * 0.9);
        EXPECT_LT(dist(out.back(), line.back()), step + 1e-6);
    }
}

// Points of a helix (radius 2 mm, pitch ~1.9 mm: curvature 0.46 /mm, about
// that of tight tractography turns) at the given spacings along its arc.
static std::vector<Vec3f> helix_points(const std::vector<double>& spacings) {
    const double radius = 2, rise = 0.3, speed = std::sqrt(radius * radius + rise * rise);
    std::vector<Vec3f> line;
    double s = 0;
    for (std::size_t i = 0; i <= spacings.size(); ++i) {
        const double t = s / speed;
        line.push_back({float(radius * std::cos(t)), float(radius * std::sin(t)), float(rise * t)});
        if (i < spacings.size()) s += spacings[i];
    }
    return line;
}

TEST(Resample, CubicKeepsTheLengthOfASmoothCurveSampledNearTheStep) {
    // Samples of a smooth curve about one step apart (as iFOD2 writes them):
    // chords of the step through the polyline cut every corner, chords of the
    // step along the cubic through the same points do not.
    std::mt19937 rng(8);
    std::uniform_real_distribution<double> spacing(0.45, 0.55);
    std::vector<double> spacings(300);
    for (double& d : spacings) d = spacing(rng);
    const std::vector<Vec3f> line = helix_points(spacings);
    const double step = 0.5, input = length_of(line);
    std::vector<Vec3f> on_polyline, on_cubic;
    resample_keeping_end(line, step, on_polyline, ResampleCurve::polyline);
    resample_keeping_end(line, step, on_cubic, ResampleCurve::cubic);
    const double polyline_loss = input - length_of(on_polyline), cubic_change = length_of(on_cubic) - input;
    EXPECT_GT(polyline_loss, 0.2 * step) << "the corners the polyline walk cuts";
    EXPECT_LT(std::fabs(cubic_change), 0.02 * step) << "polyline walk lost " << polyline_loss << " mm";
    // And every point of the cubic walk is on the helix (up to the cubic's
    // own error, ~h^4 curvature^3), not merely near the polyline.
    for (const Vec3f& p : on_cubic) {
        const double r = std::hypot(double(p.x), double(p.y));
        EXPECT_NEAR(r, 2.0, 2e-3);
    }
}

// A walk that turns by up to 40° per vertex (as tractography's sharpest)
// at irregular spacing, 0.2 to 0.9 mm.
static std::vector<Vec3f> turning_walk(std::mt19937& rng, int segments) {
    std::uniform_real_distribution<double> u(-1, 1), len(0.2, 0.9);
    const double max_turn = 40 * M_PI / 180;
    double d[3] = {1, 0, 0};
    std::vector<Vec3f> line{{0, 0, 0}};
    for (int i = 0; i < segments; ++i) {
        // d += a random perpendicular nudge of at most tan(max_turn), renormalized.
        double r[3] = {u(rng), u(rng), u(rng)};
        const double along = r[0] * d[0] + r[1] * d[1] + r[2] * d[2];
        for (int k = 0; k < 3; ++k) r[k] -= along * d[k];
        const double rn = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]) + 1e-12;
        const double nudge = std::tan(max_turn) * std::fabs(u(rng)) / rn;
        for (int k = 0; k < 3; ++k) d[k] += nudge * r[k];
        const double dn = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (double& v : d) v /= dn;
        const double l = len(rng);
        line.push_back({float(line.back().x + d[0] * l), float(line.back().y + d[1] * l), float(line.back().z + d[2] * l)});
    }
    return line;
}

TEST(Resample, LengthKeepingTensionMakesEveryFiberAsLongAsItsInput) {
    // Where the Bessel cubic is not enough (walks turning by up to 40° at
    // irregular spacing around the step; a helix sampled near the step), the fitted tension
    // brings each resampled fiber to its input's length within the fit's
    // tolerance (plus the rounding of the tension to its quantum), and
    // resampling with the returned tension gives the same points as letting
    // resample_keeping_end fit it. Both length-keeping curves (their
    // segments here are all shorter than 2 kCornerSteps steps).
    for (const ResampleCurve curve : {ResampleCurve::cubic_keeping_length, ResampleCurve::rounded_keeping_length}) {
        SCOPED_TRACE(int(curve));
        std::mt19937 rng(12);
        std::uniform_real_distribution<double> spacing(0.45, 0.55);
        int changed = 0;
        for (int trial = 0; trial < 40; ++trial) {
            std::vector<Vec3f> line;
            double step = 0.5;
            if (trial % 2 == 0) {
                line = turning_walk(rng, 120);
                step = 0.4;
            } else {
                std::vector<double> spacings(200);
                for (double& d : spacings) d = spacing(rng);
                line = helix_points(spacings);
            }
            const double input = length_of(line);
            std::vector<Vec3f> bessel, fitted, given;
            resample_keeping_end(line, step, bessel, ResampleCurve::cubic);
            resample_keeping_end(line, step, fitted, curve);
            const double tension = length_keeping_tension(line, step, 1.0, curve);
            resample_cubic_keeping_end(line, step, tension, given, nullptr, curve);
            EXPECT_EQ(fitted, given);
            EXPECT_GE(tension, 0.0);
            EXPECT_LE(tension, kMaxResampleTension);
            EXPECT_EQ(std::fmod(tension, kTensionQuantum), 0.0) << "a tension 16 bits cannot hold";
            const double bessel_change = std::fabs(length_of(bessel) - input);
            const double fitted_change = std::fabs(length_of(fitted) - input);
            EXPECT_LT(fitted_change, 2 * kLengthTolerance * step) << "trial " << trial << ", tension " << tension
                                                                  << ", Bessel's cubic was off by " << bessel_change;
            changed += bessel_change > 4 * kLengthTolerance * step;
            for (std::size_t i = 1; i + 1 < fitted.size(); ++i) EXPECT_NEAR(dist(fitted[i - 1], fitted[i]), step, 1e-5);
            EXPECT_EQ(fitted.back(), line.back());
        }
        EXPECT_GT(changed, 20) << "inputs the Bessel cubic already keeps the length of test nothing";
    }
}

TEST(Resample, RoundedCornersKeepTheLengthOfLongTurningSegments) {
    // Segments of 4 to 9 steps turning by up to 40° per vertex (a raw
    // 20-point bundle resampled at a fine step): on curve 2 such segments
    // are straight, so the chords cut every corner whatever the tension
    // (measured on cingulum-1 at a 1 mm step: 0.21 mm short on fibers of
    // 4-6 mm segments); the rounded corners of curve 3 reach the length.
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> spacing(2.0, 4.5);
    int curve2_short = 0;
    for (int trial = 0; trial < 20; ++trial) {
        // turning_walk's directions, its segments made 4 to 9 steps of 0.5 mm.
        const std::vector<Vec3f> walk = turning_walk(rng, 20);
        std::vector<Vec3f> line{walk[0]};
        for (std::size_t i = 1; i < walk.size(); ++i) {
            const double l = spacing(rng) / dist(walk[i - 1], walk[i]);
            line.push_back({float(line.back().x + l * (walk[i].x - walk[i - 1].x)),
                            float(line.back().y + l * (walk[i].y - walk[i - 1].y)),
                            float(line.back().z + l * (walk[i].z - walk[i - 1].z))});
        }
        const double step = 0.5, input = length_of(line);
        std::vector<Vec3f> old_curve, rounded;
        resample_keeping_end(line, step, old_curve, ResampleCurve::cubic_keeping_length);
        resample_keeping_end(line, step, rounded, ResampleCurve::rounded_keeping_length);
        curve2_short += input - length_of(old_curve) > 10 * kLengthTolerance * step;
        EXPECT_LT(std::fabs(length_of(rounded) - input), 2 * kLengthTolerance * step) << "trial " << trial;
        for (std::size_t i = 1; i + 1 < rounded.size(); ++i) EXPECT_NEAR(dist(rounded[i - 1], rounded[i]), step, 1e-5);
        EXPECT_EQ(rounded.back(), line.back());
        // The rounding stays near the polyline: within a corner's length
        // (kCornerSteps steps) of it, at most (4/27) |tension m - u| of it.
        double farthest = 0;
        for (const Vec3f& p : rounded) {
            double best = 1e30;
            for (std::size_t i = 1; i < line.size(); ++i) {
                const double ax = double(p.x) - line[i - 1].x, ay = double(p.y) - line[i - 1].y, az = double(p.z) - line[i - 1].z;
                const double bx = double(line[i].x) - line[i - 1].x, by = double(line[i].y) - line[i - 1].y, bz = double(line[i].z) - line[i - 1].z;
                const double t = std::clamp((ax * bx + ay * by + az * bz) / (bx * bx + by * by + bz * bz), 0.0, 1.0);
                best = std::min(best, std::hypot(ax - t * bx, ay - t * by, az - t * bz));
            }
            farthest = std::max(farthest, best);
        }
        EXPECT_LT(farthest, kCornerSteps * step * 4 / 27 * (kMaxResampleTension + 1));
    }
    EXPECT_GT(curve2_short, 10) << "inputs curve 2 already keeps the length of test nothing";
}

TEST(Resample, LengthKeepingTensionOfAStraightOrShortFiber) {
    // Nothing to fit: a straight fiber is its own curve at any tension.
    const std::vector<Vec3f> straight{{0, 0, 0}, {3.3f, 0, 0}, {7, 0, 0}};
    std::vector<Vec3f> out;
    for (const ResampleCurve curve : {ResampleCurve::cubic_keeping_length, ResampleCurve::rounded_keeping_length}) {
        resample_keeping_end(straight, 1.0, out, curve);
        EXPECT_NEAR(length_of(out), 7.0, 1e-5);
    }
    EXPECT_EQ(length_keeping_tension({}, 1.0), 1.0);
    const std::vector<Vec3f> one{{1, 2, 3}};
    EXPECT_EQ(length_keeping_tension(one, 1.0), 1.0);
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

TEST(Resample, PositionsSayWhereEachPointLiesOnTheInput) {
    // Interpolating the input's own coordinates at the positions gives back
    // the points on the polyline, and points within the cubic's distance of
    // its chord on the cubic; positions only move forward along the input.
    std::mt19937 rng(9);
    std::vector<Vec3f> line = random_walk(rng, 120);
    line.insert(line.begin() + 40, line[40]);  // a repeated point
    const std::vector<float> coords(&line[0].x, &line[0].x + 3 * line.size());
    for (const ResampleCurve curve : {ResampleCurve::polyline, ResampleCurve::cubic}) {
        std::vector<Vec3f> out;
        std::vector<PolylinePosition> at;
        resample_keeping_end(line, 0.3, out, curve, &at);
        ASSERT_EQ(at.size(), out.size());
        std::vector<Vec3f> back(out.size());
        interpolate_point_values(at, coords.data(), 3, &back[0].x);
        for (std::size_t k = 0; k < out.size(); ++k) {
            ASSERT_LT(at[k].segment + 1, line.size());
            ASSERT_GE(at[k].t, 0.0);
            ASSERT_LE(at[k].t, 1.0);
            if (k > 0) {
                EXPECT_TRUE(at[k].segment > at[k - 1].segment ||
                    (at[k].segment == at[k - 1].segment && at[k].t >= at[k - 1].t));
            }
            const double seg = dist(line[at[k].segment], line[at[k].segment + 1]);
            EXPECT_LT(dist(back[k], out[k]), curve == ResampleCurve::polyline ? 1e-5 : 0.3 * seg + 1e-5) << k;
        }
        EXPECT_EQ(back.back(), line.back());
    }
}

// Points far from the origin (x = 4e28 mm, all equal in float, as a .trk
// whose affine translates them so) and 3 mm apart in z: every curve's walk
// gives the points of its z extent at the step, as at the origin. The
// cubic evaluated from its end points, not as a weighted sum of them, so
// that their rounding (1e12 mm in double) is not in the curve (the fuzzer
// found compress filling memory on such a file).
TEST(Resample, CoordinatesFarLargerThanTheCurveResampleAsAtTheOrigin) {
    // The fuzzer's fiber: 3, 3, 2.75 and 3.25 mm apart.
    const std::vector<Vec3f> near{{0, 1.5726964e-30f, 2}, {0, 6.2908038e-30f, 5}, {0, 1.1008911e-29f, 8},
                                  {0, 1.5727019e-29f, 10.75f}, {0, 2.0445126e-29f, 14}};
    std::vector<Vec3f> far = near;
    for (Vec3f& p : far) p.x = 4.1780774e28f;
    for (const ResampleCurve curve : {ResampleCurve::polyline, ResampleCurve::cubic, ResampleCurve::cubic_keeping_length,
                                      ResampleCurve::rounded_keeping_length}) {
        std::vector<Vec3f> a, b;
        resample_fixed_step(near, 0.75, a, curve);
        resample_fixed_step(far, 0.75, b, curve);
        ASSERT_EQ(b.size(), a.size()) << int(curve);
        for (std::size_t i = 0; i < a.size(); ++i) {
            EXPECT_EQ(b[i].x, far[0].x);
            EXPECT_NEAR(b[i].z, a[i].z, 1e-5) << int(curve) << " point " << i;
        }
        EXPECT_GE(a.size(), 16u);  // 12 mm at 0.75 mm
    }
}
