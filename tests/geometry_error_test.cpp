// GeometryError (the symmetric metrics of compress / stats / Python) against
// a brute-force O(n·m) implementation written here, independently of the
// library: every point against every segment of the other polyline.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"
#include "fiblet/geometry_error.hpp"
#include "stats/geometry_paths.hpp"
#include "scoped_simd_loops.hpp"
#include "test_util.hpp"

namespace fiblet {
namespace {

using Line = std::vector<Vec3f>;

// Closest distance from p to segment [a, b], by projection, in long double.
long double brute_segment(Vec3f p, Vec3f a, Vec3f b) {
    const long double ux = (long double)b.x - a.x, uy = (long double)b.y - a.y, uz = (long double)b.z - a.z;
    const long double wx = (long double)p.x - a.x, wy = (long double)p.y - a.y, wz = (long double)p.z - a.z;
    const long double uu = ux * ux + uy * uy + uz * uz;
    long double t = uu > 0 ? (wx * ux + wy * uy + wz * uz) / uu : 0;
    t = std::clamp<long double>(t, 0, 1);
    const long double dx = wx - t * ux, dy = wy - t * uy, dz = wz - t * uz;
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}

long double brute_to_line(Vec3f p, const Line& l) {
    if (l.size() == 1) return brute_segment(p, l[0], l[0]);
    long double best = INFINITY;
    for (std::size_t s = 0; s + 1 < l.size(); ++s) best = std::min(best, brute_segment(p, l[s], l[s + 1]));
    return best;
}

struct Brute {
    long double max_di = 0, sum_di = 0, max_id = 0, sum_id = 0, end_max = 0, end_sum = 0, len_max = 0, len_sum = 0;
    std::size_t n_di = 0, n_id = 0, fibers = 0;
};

long double brute_length(const Line& l) {
    long double s = 0;
    for (std::size_t i = 1; i < l.size(); ++i) s += brute_segment(l[i], l[i - 1], l[i - 1]);
    return s;
}

void brute_add(Brute& b, const Line& in, const Line& dec) {
    for (Vec3f p : dec) {
        const long double d = brute_to_line(p, in);
        b.max_di = std::max(b.max_di, d), b.sum_di += d, ++b.n_di;
    }
    for (Vec3f p : in) {
        const long double d = brute_to_line(p, dec);
        b.max_id = std::max(b.max_id, d), b.sum_id += d, ++b.n_id;
    }
    const long double e0 = brute_segment(in.front(), dec.front(), dec.front());
    const long double e1 = brute_segment(in.back(), dec.back(), dec.back());
    b.end_max = std::max({b.end_max, e0, e1}), b.end_sum += e0 + e1;
    const long double dl = std::fabs(brute_length(dec) - brute_length(in));
    b.len_max = std::max(b.len_max, dl), b.len_sum += dl;
    ++b.fibers;
}

// A wiggly curve, optionally looping back over itself, sampled every `step`.
Line curve(int points, double step, double loop_radius, std::mt19937& rng, double noise) {
    std::normal_distribution<double> n(0, noise);
    Line l;
    for (int i = 0; i < points; ++i) {
        const double s = i * step;
        const double t = loop_radius > 0 ? s / loop_radius : 0;
        l.push_back({float((loop_radius > 0 ? loop_radius * std::cos(t) : s) + n(rng)),
                     float((loop_radius > 0 ? loop_radius * std::sin(t) : std::sin(s)) + n(rng)), float(0.05 * s + n(rng))});
    }
    return l;
}

void expect_matches_brute(const std::vector<std::pair<Line, Line>>& pairs) {
    GeometryError g;
    Brute b;
    for (std::size_t i = 0; i < pairs.size(); ++i) {
        g.add_fiber(pairs[i].first, pairs[i].second, i);
        brute_add(b, pairs[i].first, pairs[i].second);
    }
    // Point-to-polyline distances are float arithmetic on the float points:
    // each within a few float ulps of the segment's extent (~1e-8 mm here),
    // far below a wrong nearest segment's error; the rest is double.
    const double tol = 1e-9, float_tol = 1e-7;
    EXPECT_NEAR(g.decoded_to_input().max_mm(), double(b.max_di), float_tol);
    EXPECT_NEAR(g.decoded_to_input().mean_mm(), double(b.sum_di / b.n_di), float_tol);
    EXPECT_NEAR(g.input_to_decoded().max_mm(), double(b.max_id), float_tol);
    EXPECT_NEAR(g.input_to_decoded().mean_mm(), double(b.sum_id / b.n_id), float_tol);
    EXPECT_NEAR(g.hausdorff_mm(), double(std::max(b.max_di, b.max_id)), float_tol);
    EXPECT_NEAR(g.endpoint_mm().max, double(b.end_max), tol);
    EXPECT_NEAR(g.endpoint_mm().mean(), double(b.end_sum / (2 * b.fibers)), tol);
    EXPECT_NEAR(g.length_change_mm().max, double(b.len_max), 1e-7);
    EXPECT_NEAR(g.length_change_mm().mean(), double(b.len_sum / b.fibers), 1e-7);
}

TEST(GeometryError, MatchesBruteForceOnPerturbedResampledCurves) {
    std::mt19937 rng(11);
    std::vector<std::pair<Line, Line>> pairs;
    for (int k = 0; k < 20; ++k) {
        const Line in = curve(30 + k * 7, 0.1 * (1 + k % 3), 0, rng, 0);
        Line dec = curve(int(in.size()) * (1 + k % 4), 0.1 * (1 + k % 3) / (1 + k % 4), 0, rng, 0.003);
        pairs.emplace_back(in, dec);
    }
    expect_matches_brute(pairs);
}

TEST(GeometryError, MatchesBruteForceOnLoopsAndSparseInput) {
    std::mt19937 rng(5);
    std::vector<std::pair<Line, Line>> pairs;
    for (int k = 0; k < 8; ++k) {
        // 1.3 turns of a circle: the end passes near the start.
        const double r = 1 + k;
        const int dense = int(1.3 * 2 * M_PI * r / 0.1);
        Line in = curve(dense / 20 + 2, 0.1 * double(dense) / double(dense / 20 + 1), r, rng, 0);  // sparse input
        Line dec = curve(dense, 0.1, r, rng, 0.002);
        pairs.emplace_back(in, dec);
    }
    expect_matches_brute(pairs);
}

// A sparse input spaced unevenly (0.2 mm segments, then 20 mm ones), as
// compress resamples it: input -> decoded must find the dense polyline's
// segments 100 ahead (the window once reached 23 and reported 61 mm).
TEST(GeometryError, MatchesBruteForceOnUnevenlySpacedSparseInput) {
    std::mt19937 rng(9);
    std::normal_distribution<double> noise(0, 0.002);
    std::vector<std::pair<Line, Line>> pairs;
    for (int k = 0; k < 6; ++k) {
        Line in;
        for (int i = 0; i < 16; ++i) in.push_back({0.2f * float(i), float(k), std::sin(0.02f * float(i))});
        for (int i = 1; i <= 4 + k; ++i) in.push_back({3.0f + 20.0f * float(i), float(k), std::sin(0.3f * float(i))});
        Line dec;  // the input resampled every ~0.2 mm, with noise
        for (std::size_t s = 0; s + 1 < in.size(); ++s) {
            const int parts = std::max(1, int(std::lround(std::sqrt(double(brute_segment(in[s], in[s + 1], in[s + 1]))) / 0.2)));
            for (int j = 0; j < parts; ++j) {
                const float t = float(j) / float(parts);
                dec.push_back({in[s].x + t * (in[s + 1].x - in[s].x) + float(noise(rng)),
                               in[s].y + t * (in[s + 1].y - in[s].y) + float(noise(rng)),
                               in[s].z + t * (in[s + 1].z - in[s].z) + float(noise(rng))});
            }
        }
        dec.push_back(in.back());
        pairs.emplace_back(in, dec);
    }
    expect_matches_brute(pairs);
}

TEST(GeometryError, ADroppedTailCountsOneWayOnly) {
    Line in, dec;
    for (int i = 0; i <= 100; ++i) in.push_back({float(0.1 * i), 0, 0});
    for (int i = 0; i <= 90; ++i) dec.push_back({float(0.1 * i), 0, 0});
    GeometryError g;
    g.add_fiber(in, dec, 0);
    EXPECT_NEAR(g.decoded_to_input().max_mm(), 0.0, 1e-6);  // what the old metric saw
    EXPECT_NEAR(g.input_to_decoded().max_mm(), 1.0, 1e-5);
    EXPECT_NEAR(g.hausdorff_mm(), 1.0, 1e-5);
    EXPECT_NEAR(g.endpoint_mm().max, 1.0, 1e-5);
    EXPECT_NEAR(g.length_change_mm().max, 1.0, 1e-5);
    EXPECT_NEAR(g.length_change_percent().max, 10.0, 1e-3);
    EXPECT_NEAR(g.mean_length_change_mm(), -1.0, 1e-5);
    EXPECT_NEAR(g.worst_mm(), 1.0, 1e-5);
}

TEST(GeometryError, MergeEqualsOneAccumulator) {
    std::mt19937 rng(2);
    GeometryError all, a, b;
    for (int k = 0; k < 10; ++k) {
        const Line in = curve(50, 0.1, 0, rng, 0), dec = curve(50, 0.1, 0, rng, 0.01);
        all.add_fiber(in, dec, k);
        (k % 2 ? a : b).add_fiber(in, dec, k);
    }
    a.merge(b);
    EXPECT_DOUBLE_EQ(a.hausdorff_mm(), all.hausdorff_mm());
    EXPECT_EQ(a.hausdorff_fiber(), all.hausdorff_fiber());
    EXPECT_NEAR(a.input_to_decoded().mean_mm(), all.input_to_decoded().mean_mm(), 1e-15);
    EXPECT_DOUBLE_EQ(a.endpoint_mm().max, all.endpoint_mm().max);
    EXPECT_NEAR(a.length_change_mm().mean(), all.length_change_mm().mean(), 1e-15);
}


// Fixed-step pairs (as many decoded points as input points: the path that
// evaluates a window ahead of the hint), from 1 to 400 points, with repeated
// points (zero-length segments) and decoded points about 1 to 30 µm off (codec errors; the window is a
// heuristic: decoded points half a step off can miss the nearest segment).
std::vector<std::pair<Line, Line>> fixed_step_pairs() {
    std::mt19937 rng(17);
    std::vector<std::pair<Line, Line>> pairs;
    for (int k = 0; k < 40; ++k) {
        const int n = k < 14 ? k + 1 : 30 + 9 * k;  // 1 .. 14 points: every vector loop's edges
        Line in = curve(n, 0.1, k % 5 == 0 ? 2.0 : 0, rng, 0);
        if (n > 6) in[n / 2] = in[n / 2 - 1];  // a zero-length segment
        std::normal_distribution<double> e(0, k % 3 == 0 ? 0.01 : 0.002);
        Line dec = in;
        for (Vec3f& p : dec) p = {float(p.x + e(rng)), float(p.y + e(rng)), float(p.z + e(rng))};
        pairs.emplace_back(in, dec);
    }
    return pairs;
}

TEST(GeometryError, MatchesBruteForceOnFixedStepPairs) { expect_matches_brute(fixed_step_pairs()); }

std::vector<std::pair<Line, Line>> folded_pairs() {
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> turn(100, 178);
    std::vector<std::pair<Line, Line>> pairs;
    for (int k = 0; k < 40; ++k) {
        const double step = 0.1;
        Line in{{0, 0, 0}};
        double heading = 0, climb = k % 2 ? 0.3 : 0.0;  // flat ones fold back onto themselves
        for (int i = 1; i < 40 + 5 * k; ++i) {
            heading += i % 7 == 0 ? (i % 2 ? 1 : -1) * turn(rng) * M_PI / 180 : 0.05;
            const Vec3f q = in.back();
            in.push_back({float(q.x + step * std::cos(heading) * std::cos(climb)),
                          float(q.y + step * std::sin(heading) * std::cos(climb)), float(q.z + step * std::sin(climb))});
        }
        if (k % 4 == 0) in[10] = in[9];  // a zero-length segment
        std::normal_distribution<double> e(0, step * (k % 3 == 0 ? 0.15 : 0.05));
        Line dec = in;
        for (Vec3f& p : dec) p = {float(p.x + e(rng)), float(p.y + e(rng)), float(p.z + e(rng))};
        pairs.emplace_back(in, dec);
    }
    return pairs;
}

GeometryError measure_pairs(const std::vector<std::pair<Line, Line>>& pairs) {
    GeometryError g;
    for (std::size_t i = 0; i < pairs.size(); ++i) g.add_fiber(pairs[i].first, pairs[i].second, i);
    return g;
}

void expect_same_bits(const ErrorStats& x, const ErrorStats& y) {
    EXPECT_EQ(x.count(), y.count());
    EXPECT_EQ(x.max_mm(), y.max_mm());
    EXPECT_EQ(x.mean_mm(), y.mean_mm());
    EXPECT_EQ(x.rms_mm(), y.rms_mm());
    for (double p : {50.0, 99.0}) EXPECT_EQ(x.percentile_mm(p), y.percentile_mm(p)) << p;
    EXPECT_EQ(x.worst_fiber(), y.worst_fiber());
}

void expect_same_bits(const GeometryError& a, const GeometryError& b) {
    for (auto pick : {&GeometryError::decoded_to_input, &GeometryError::input_to_decoded})
        expect_same_bits((a.*pick)(), (b.*pick)());
    EXPECT_EQ(a.endpoint_mm().max, b.endpoint_mm().max);
    EXPECT_EQ(a.length_change_mm().sum, b.length_change_mm().sum);
    EXPECT_EQ(a.mean_length_change_mm(), b.mean_length_change_mm());
}

// Coordinates in any units: the report of a pair scaled by 2^e is the
// report scaled by 2^e, bit for bit, far beyond float's squares (steps of
// 1e23 mm, of 1e-31 mm: measured scaled into range, geometry_error.cpp), for
// fixed-step pairs (the shortcut and the window) and for unevenly resampled
// ones; and far from the origin the figures are those near it.
TEST(GeometryError, ScaledCoordinatesScaleTheReport) {
    std::vector<std::pair<Line, Line>> pairs = fixed_step_pairs(), folded = folded_pairs();
    pairs.insert(pairs.end(), folded.begin(), folded.end());
    std::mt19937 rng(29);
    for (int k = 0; k < 6; ++k) {
        const Line in = curve(20 + 9 * k, 0.2 * (1 + k % 3), 0, rng, 0);
        pairs.emplace_back(in, curve(int(in.size()) * (2 + k % 3), 0.2 * (1 + k % 3) / (2 + k % 3), 0, rng, 0.004));
    }
    const GeometryError plain = measure_pairs(pairs);
    for (const int e : {82, -100, 12}) {
        SCOPED_TRACE(testing::Message() << "scale 2^" << e);
        std::vector<std::pair<Line, Line>> scaled = pairs;
        for (auto& [in, dec] : scaled)
            for (Line* l : {&in, &dec})
                for (Vec3f& p : *l) p = {std::ldexp(p.x, e), std::ldexp(p.y, e), std::ldexp(p.z, e)};
        const GeometryError g = measure_pairs(scaled);
        for (auto pick : {&GeometryError::decoded_to_input, &GeometryError::input_to_decoded}) {
            const ErrorStats &x = (g.*pick)(), &y = (plain.*pick)();
            EXPECT_EQ(x.count(), y.count());
            EXPECT_EQ(x.max_mm(), std::ldexp(y.max_mm(), e));
            EXPECT_EQ(x.mean_mm(), std::ldexp(y.mean_mm(), e));
            EXPECT_EQ(x.worst_fiber(), y.worst_fiber());
        }
        EXPECT_EQ(g.hausdorff_mm(), std::ldexp(plain.hausdorff_mm(), e));
        EXPECT_EQ(g.endpoint_mm().max, std::ldexp(plain.endpoint_mm().max, e));
        EXPECT_EQ(g.length_change_mm().sum, std::ldexp(plain.length_change_mm().sum, e));
    }
    // Far from the origin, the same figures: every x at 2^95 mm (the
    // fuzzer's .trk translated by 4e28 mm) against every x at 0.
    std::vector<std::pair<Line, Line>> near = pairs, far = pairs;
    for (auto* set : {&near, &far})
        for (auto& [in, dec] : *set)
            for (Line* l : {&in, &dec})
                for (Vec3f& p : *l) p.x = set == &far ? 0x1p95f : 0.0f;
    expect_same_bits(measure_pairs(far), measure_pairs(near));
}

// Fixed-step pairs where a point's two own segments are not provably the
// nearest (the shortcut of geometry_error.cpp): fibers that fold back by up
// to 178 degrees, repeated points, decoded points up to 40 % of a step off.
// The shortcut must give the full window's figures bit for bit (the window
// itself is a heuristic: folded fibers can fool it, so brute force is not
// the reference here), and must be taken on most points of well-behaved
// fixed-step fibers, where both match brute force (previous test).
TEST(GeometryError, ShortcutEqualsTheWindowOnFoldedFixedStepPairs) {
    const auto pairs = folded_pairs();
    const GeometryError with = measure_pairs(pairs);
    detail::geometry_shortcut_enabled() = false;
    const GeometryError without = measure_pairs(pairs);
    detail::geometry_shortcut_enabled() = true;
    expect_same_bits(with, without);
}

// The AVX-512 loops (the fixed-step shortcut's proof) and the AVX2 loops
// (columns, the proof, the windows, square roots) give the scalar loops'
// figures bit for bit, on fixed-step pairs (shortcut taken or not), folded
// ones and pairs of different point counts; where the CPU lacks AVX-512 or
// AVX2 those runs take the narrower loops.
TEST(GeometryError, VectorsEqualScalarLoops) {
    std::mt19937 rng(31);
    std::vector<std::pair<Line, Line>> pairs = fixed_step_pairs(), folded = folded_pairs();
    pairs.insert(pairs.end(), folded.begin(), folded.end());
    for (int k = 0; k < 10; ++k) {
        const Line in = curve(30 + k * 7, 0.1 * (1 + k % 3), 0, rng, 0);
        pairs.emplace_back(in, curve(int(in.size()) * (1 + k % 4), 0.1 * (1 + k % 3) / (1 + k % 4), 0, rng, 0.003));
    }
    for (const bool shortcut : {true, false}) {
        detail::geometry_shortcut_enabled() = shortcut;
        const GeometryError widest = measure_pairs(pairs);
        const GeometryError avx2 = test::with_simd_loops(true, false, [&] { return measure_pairs(pairs); });
        const GeometryError scalar = test::with_simd_loops(false, false, [&] { return measure_pairs(pairs); });
        expect_same_bits(widest, scalar);
        expect_same_bits(avx2, scalar);
    }
    detail::geometry_shortcut_enabled() = true;
}

// The vector loops skip a polyline's forward tests where every turn is
// under 28 degrees: there, every pair of segments up to three apart has a
// non-negative float dot product (what the tests would have found). Planar
// curls turning the same way by 27 degrees a step are skipped, by 31 (three
// steps: 93 degrees, a negative dot) and 50 degrees never; random 3-D turns
// up to 10 to 60 degrees are checked against the tests themselves.
TEST(GeometryError, ForwardTestsAreSkippedOnlyWhereTheyHold) {
    auto planar_curl = [](double degrees, int n) {
        Line l{{10, 20, 30}};
        for (int i = 1; i < n; ++i) {
            const double a = i * degrees * M_PI / 180;
            l.push_back({float(l.back().x + 0.1 * std::cos(a)), float(l.back().y + 0.1 * std::sin(a)), l.back().z});
        }
        return l;
    };
    auto forward_tests_hold = [](const Line& l) {
        auto u = [&](std::size_t s) {
            return Vec3f{l[s + 1].x - l[s].x, l[s + 1].y - l[s].y, l[s + 1].z - l[s].z};
        };
        for (std::size_t s = 0; s + 1 < l.size(); ++s)
            for (std::size_t t = s + 1; t <= s + 3 && t + 1 < l.size(); ++t) {
                const Vec3f a = u(s), b = u(t);
                if (!(a.x * b.x + a.y * b.y + a.z * b.z >= 0)) return false;
            }
        return true;
    };
    const bool vectors = detail::use_avx2_loops();
    for (const int n : {10, 17, 64, 301}) {
        EXPECT_EQ(detail::forward_tests_skipped(planar_curl(27, n)), vectors) << n;
        EXPECT_FALSE(forward_tests_hold(planar_curl(31, n))) << n;
        EXPECT_FALSE(detail::forward_tests_skipped(planar_curl(31, n))) << n;
        EXPECT_FALSE(detail::forward_tests_skipped(planar_curl(50, n))) << n;
    }
    std::mt19937 rng(37);
    int skipped = 0;
    for (const double max_turn : {10.0, 27.0, 29.0, 45.0, 60.0})
        for (int k = 0; k < 40; ++k) {
            std::uniform_real_distribution<double> turn(0, max_turn * M_PI / 180);
            std::normal_distribution<double> g(0, 1);
            Line l{{0, 0, 0}};
            double d[3] = {1, 0, 0};
            for (int i = 1; i < 20 + 7 * k; ++i) {
                // d turned by `turn` towards q, a random direction perpendicular to it.
                double q[3] = {g(rng), g(rng), g(rng)}, along = 0, norm = 0;
                for (int a = 0; a < 3; ++a) along += q[a] * d[a];
                for (int a = 0; a < 3; ++a) q[a] -= along * d[a], norm += q[a] * q[a];
                const double t = turn(rng);
                for (int a = 0; a < 3; ++a) d[a] = std::cos(t) * d[a] + std::sin(t) * q[a] / std::sqrt(norm);
                l.push_back({float(l.back().x + 0.1 * d[0]), float(l.back().y + 0.1 * d[1]), float(l.back().z + 0.1 * d[2])});
            }
            const bool skip = detail::forward_tests_skipped(l);
            skipped += skip;
            if (skip) {
                EXPECT_TRUE(forward_tests_hold(l)) << max_turn << " " << k;
            }
            if (max_turn <= 27 && vectors) {
                EXPECT_TRUE(skip) << max_turn << " " << k;
            }
        }
    if (vectors) {
        EXPECT_GE(skipped, 80);
    }
}

// add_fiber's pointwise squares (compress's point errors of fixed-step
// input, taken from the report's own computation): each is the pair's
// squared distance in double, ((dx dx + dy dy) + dz dz), whichever loops
// and path (the shortcut's proof or the window) measured the pair; the
// report itself does not change; a span of the wrong size is refused.
TEST(GeometryError, PointwiseSquaresAreEachPairsDistance) {
    std::vector<std::pair<Line, Line>> pairs = fixed_step_pairs(), folded = folded_pairs();
    pairs.insert(pairs.end(), folded.begin(), folded.end());
    const GeometryError plain = measure_pairs(pairs);
    for (const bool shortcut : {true, false})
        for (const bool avx2 : {true, false}) {
            SCOPED_TRACE(testing::Message() << "shortcut " << shortcut << " avx2 " << avx2);
            detail::geometry_shortcut_enabled() = shortcut;
            const test::ScopedSimdLoops loops(avx2);
            GeometryError g;
            for (std::size_t i = 0; i < pairs.size(); ++i) {
                const auto& [in, dec] = pairs[i];
                std::vector<double> e2(in.size(), -1.0);
                g.add_fiber(in, dec, i, e2);
                for (std::size_t k = 0; k < in.size(); ++k) {
                    const double dx = double(in[k].x) - double(dec[k].x), dy = double(in[k].y) - double(dec[k].y),
                                 dz = double(in[k].z) - double(dec[k].z);
                    ASSERT_EQ(e2[k], (dx * dx + dy * dy) + dz * dz) << "fiber " << i << " point " << k;
                }
            }
            expect_same_bits(g, plain);
        }
    detail::geometry_shortcut_enabled() = true;
    std::mt19937 rng(5);
    const Line in = curve(20, 0.1, 0, rng, 0);
    std::vector<double> wrong(in.size() - 1);
    GeometryError g;
    EXPECT_THROW(g.add_fiber(in, in, 0, wrong), Error);
    Line shorter(in.begin(), in.end() - 1);
    EXPECT_THROW(g.add_fiber(in, shorter, 0, std::span<double>(wrong.data(), in.size() - 1)), Error);
}

// The same end to end: compress's every AVX-512 and AVX2 loop over points
// (the reader's finiteness check, the scan's turns, the header's point
// errors, the symmetric metrics) switched off gives the same file and the
// same report, bit for bit; fixed-step input and resampled input (its
// uneven windows). One thread: the switches are per thread, and one thread
// runs every task on the caller.
TEST(GeometryError, CompressReportsTheSameBitsWithoutAvx2Loops) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    CompressOptions o;
    o.overwrite = true;
    o.threads = 1;
    for (const double step : {0.0, 0.5}) {
        SCOPED_TRACE(step);
        o.step_mm = step > 0 ? std::optional<double>(step) : std::nullopt;
        const std::string tck = test::shared_data(step > 0 ? "small-sdstream.tck" : "small-ifod1.tck");
        const CompressReport vectors = compress_file(tck, dir.file("v.fft"), o);
        const CompressReport avx2 =
            test::with_simd_loops(true, false, [&] { return compress_file(tck, dir.file("a.fft"), o); });
        const CompressReport scalar =
            test::with_simd_loops(false, false, [&] { return compress_file(tck, dir.file("s.fft"), o); });
        EXPECT_TRUE(test::read_file(dir.file("v.fft")) == test::read_file(dir.file("s.fft")));
        EXPECT_TRUE(test::read_file(dir.file("a.fft")) == test::read_file(dir.file("s.fft")));
        expect_same_bits(avx2.geometry, scalar.geometry);
        expect_same_bits(vectors.geometry, scalar.geometry);
        for (auto pick : {&CompressReport::error, &CompressReport::error_vs_original})
            expect_same_bits(vectors.*pick, scalar.*pick);
        EXPECT_EQ(vectors.scan.min_dot, scalar.scan.min_dot);
        EXPECT_EQ(vectors.scan.step_mean, scalar.scan.step_mean);
    }
}

}  // namespace
}  // namespace fiblet
