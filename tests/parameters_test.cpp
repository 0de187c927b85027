// The encoder's free choices: turning-angle statistics against brute force,
// the deterministic fiber sample, and the tuning of cap ratio and step.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "compress/compress_stages.hpp"
#include "encode/parameters.hpp"
#include "scoped_simd_loops.hpp"

using namespace fiblet;
using namespace fiblet::detail;

namespace {

std::vector<Vec3f> walk(int points, double max_turn_deg, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    double p[3] = {0, 0, 0}, d[3] = {1, 0, 0};
    std::vector<Vec3f> f;
    const double s = std::tan(max_turn_deg * M_PI / 180) / std::sqrt(3.0);
    for (int k = 0; k < points; ++k) {
        f.push_back({float(p[0]), float(p[1]), float(p[2])});
        for (double& c : d) c += s * u(rng);
        const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int a = 0; a < 3; ++a) d[a] /= n, p[a] += 0.1 * d[a];
    }
    return f;
}

// Turning angles by brute force (double precision).
std::vector<double> turn_angles(const std::vector<Vec3f>& f) {
    std::vector<double> out;
    for (std::size_t i = 2; i < f.size(); ++i) {
        double a[3] = {double(f[i - 1].x) - f[i - 2].x, double(f[i - 1].y) - f[i - 2].y, double(f[i - 1].z) - f[i - 2].z};
        double b[3] = {double(f[i].x) - f[i - 1].x, double(f[i].y) - f[i - 1].y, double(f[i].z) - f[i - 1].z};
        const double c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) /
                         std::sqrt((a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) * (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]));
        out.push_back(std::acos(std::clamp(c, -1.0, 1.0)));
    }
    return out;
}

}  // namespace

TEST(TurnStatistics, PercentilesAndSharpestTurnMatchBruteForce) {
    TurnStatistics turns(60, 4);
    std::vector<double> all;
    for (unsigned s = 0; s < 20; ++s) {
        const auto f = walk(500, 5 + s, s);
        turns.add_fiber(f);
        const auto a = turn_angles(f);
        all.insert(all.end(), a.begin(), a.end());
    }
    std::sort(all.begin(), all.end());
    ASSERT_EQ(turns.count(), all.size());
    EXPECT_NEAR(std::acos(turns.min_dot()), all.back(), 1e-3);
    for (double p : {50.0, 90.0, 99.0, 99.9}) {
        const double expected = all[std::size_t(std::ceil(p / 100 * double(all.size()))) - 1];
        const double got = std::acos(turns.dot_at_percentile(p));
        EXPECT_GE(got, expected - 1e-3) << p;                // the histogram rounds up to a bin edge
        EXPECT_LE(got, expected + 0.02 * M_PI / 180 + 1e-3) << p;
    }
    EXPECT_EQ(turns.dot_at_percentile(100), turns.min_dot());
}

TEST(TurnStatistics, KeepsTheBlocksOfTheSharpestTurns) {
    TurnStatistics turns(10, 2);
    // Three straight fibers with one kink each, of 20, 40 and 30 degrees.
    for (double kink : {20.0, 40.0, 30.0}) {
        std::vector<Vec3f> f;
        const double a = kink * M_PI / 180;
        for (int k = 0; k <= 25; ++k) f.push_back({float(0.1 * std::min(k, 15)), 0, 0});
        for (int k = 16; k <= 25; ++k)
            f[k] = {float(1.5 + 0.1 * (k - 15) * std::cos(a)), float(0.1 * (k - 15) * std::sin(a)), 0};
        turns.add_fiber(f);
    }
    const auto blocks = turns.sharpest_blocks();
    ASSERT_EQ(blocks.size(), 2u);
    for (const auto& b : blocks) {
        ASSERT_EQ(b.size(), 10u);  // the block holding point 15: points 10..19
        const double kink = std::atan2(double(b.back().y), double(b.back().x) - 1.5) * 180 / M_PI;
        EXPECT_TRUE(std::fabs(kink - 40) < 0.1 || std::fabs(kink - 30) < 0.1) << kink;
    }
}

// The scan's AVX2 loops (segments and their lengths, the turns of fibers with no
// zero-length segment) against the scalar ones, bit for bit: lengths
// against |b - a| computed here, the statistics against the same fibers
// with the AVX2 loops switched off and against add_fiber's own square roots.
TEST(TurnStatistics, VectorLoopsEqualTheScalarLoops) {
    std::vector<std::vector<Vec3f>> fibers;
    for (int n = 1; n < 40; ++n) fibers.push_back(walk(n, 30, unsigned(n)));
    for (unsigned s = 0; s < 10; ++s) fibers.push_back(walk(100 + 37 * int(s), 5 + 15 * s, s));
    fibers[45][50] = fibers[45][49];  // a zero-length segment
    std::vector<Vec3f> back{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {1, 0, 0}, {0, 0, 0}, {0, 1, 0}, {0, 2, 0}, {0, 3, 0}};
    fibers.push_back(back);  // turns of 180 degrees: sin^2 clamped at 1
    // Blocks of one point: the kept block is where the sharpest turn is.
    TurnStatistics vectors(1, fibers.size()), scalar(1, fibers.size()), roots(1, fibers.size());
    FiberSegments segments, scalar_segments;
    for (const auto& f : fibers) {
        fiber_segments(f, segments);
        ASSERT_EQ(segments.length.size(), f.size() - 1);
        for (std::size_t s = 0; s + 1 < f.size(); ++s) {
            const double dx = double(f[s + 1].x) - f[s].x, dy = double(f[s + 1].y) - f[s].y, dz = double(f[s + 1].z) - f[s].z;
            const double length = std::sqrt(dx * dx + dy * dy + dz * dz);
            ASSERT_EQ(segments.length[s], length) << f.size() << " " << s;
            if (length > 0) {  // add_turns' unit direction
                ASSERT_EQ(segments.ux[s], dx * (1.0 / length));
                ASSERT_EQ(segments.uy[s], dy * (1.0 / length));
                ASSERT_EQ(segments.uz[s], dz * (1.0 / length));
            }
        }
        EXPECT_EQ(segments.positive, std::all_of(segments.length.begin(), segments.length.end(), [](double l) { return l > 0; }));
        TurnStatistics one_vectors(1, 1), one_scalar(1, 1);  // this fiber's sharpest turn, to the bit
        vectors.add_fiber(f, segments), one_vectors.add_fiber(f, segments);
        roots.add_fiber(f);
        {
            const test::ScopedSimdLoops loops(false);
            fiber_segments(f, scalar_segments);
            scalar.add_fiber(f, scalar_segments), one_scalar.add_fiber(f, scalar_segments);
        }
        ASSERT_EQ(segments.length, scalar_segments.length);
        for (std::size_t s = 0; s < segments.length.size(); ++s)  // NaN where a length is 0
            if (segments.length[s] > 0) {
                ASSERT_EQ(segments.ux[s], scalar_segments.ux[s]) << s;
            }
        ASSERT_EQ(segments.positive, scalar_segments.positive);
        EXPECT_EQ(one_vectors.min_dot(), one_scalar.min_dot()) << f.size();
        EXPECT_EQ(one_vectors.sharpest_blocks(), one_scalar.sharpest_blocks()) << f.size();
    }
    for (const TurnStatistics* other : {&scalar, &roots}) {
        EXPECT_EQ(vectors.count(), other->count());
        EXPECT_EQ(vectors.min_dot(), other->min_dot());
        for (double p : {1.0, 50.0, 90.0, 99.0, 99.9}) EXPECT_EQ(vectors.dot_at_percentile(p), other->dot_at_percentile(p)) << p;
        EXPECT_EQ(vectors.sharpest_blocks(), other->sharpest_blocks());
    }
    EXPECT_EQ(vectors.min_dot(), -1.0);
}

TEST(FiberSample, IsAnEveryKthSubsetWithinItsSize) {
    FiberSample sample(1000);
    std::vector<std::vector<Vec3f>> all;
    for (int i = 0; i < 100; ++i) {
        all.push_back(std::vector<Vec3f>(37, Vec3f{float(i), 0, 0}));
        sample.offer(all.back());
    }
    EXPECT_LE(sample.points(), 1000u);
    ASSERT_GE(sample.fibers().size(), 13u);  // 1000 / 37 / 2
    const std::size_t stride = std::size_t(sample.fibers()[1][0].x - sample.fibers()[0][0].x);
    for (std::size_t i = 0; i < sample.fibers().size(); ++i) EXPECT_EQ(std::size_t(sample.fibers()[i][0].x), i * stride);
}

TEST(TuneParameters, ChoosesAmongItsCandidatesAndNeverWorseThanTheFullCap) {
    FiberSample sample(20000);
    TurnStatistics turns(60, 8);
    for (unsigned s = 0; s < 30; ++s) {
        const auto f = walk(600, 12, 100 + s);
        sample.offer(f);
        turns.add_fiber(f);
    }
    FftHeader h;
    h.scaling = 100;
    const SearchOptions greedy{1, 1, 0, 1, 0};
    const TunedParameters t =
        tune_parameters({sample.fibers(), turns.sharpest_blocks(), 0}, turns, h, greedy, 0.1, std::nullopt, std::nullopt);
    const float full = compute_ratio(h.scaling, 0.1, turns.min_dot());
    const float smallest = compute_ratio(h.scaling, 0.1, turns.dot_at_percentile(99.9));
    EXPECT_LE(t.ratio, full * 1.0001f);
    EXPECT_GE(t.ratio, smallest * 0.9999f);
    EXPECT_GE(t.step_scale, 1.0);
    EXPECT_LE(t.step_scale, 1.0015);
    ASSERT_TRUE(t.encoder.has_value());
    // The choice measures at least as well as the full cap with the plain step.
    const TuningSet set{sample.fibers(), turns.sharpest_blocks(), 0};
    FftHeader a = h, b = h;
    a.ratio = t.ratio, a.step = float(0.1 * t.step_scale / h.scaling);
    b.ratio = full, b.step = float(0.1 / h.scaling);
    EXPECT_LE(measure(set, FiberEncoder(a, greedy)).objective(), measure(set, FiberEncoder(b, greedy)).objective());
    // Fixed choices are kept.
    const TunedParameters f =
        tune_parameters({sample.fibers(), {}, 0}, turns, h, greedy, 0.1, 0.05f, 1.0);
    EXPECT_EQ(f.ratio, 0.05f);
    EXPECT_EQ(f.step_scale, 1.0);
}

TEST(TuneParameters, SetsTheRetryThresholdFromTheMeanError) {
    FiberSample sample(20000);
    TurnStatistics turns(60, 8);
    for (unsigned s = 0; s < 10; ++s) {
        const auto f = walk(600, 12, 200 + s);
        sample.offer(f);
        turns.add_fiber(f);
    }
    FftHeader h;
    h.scaling = 100;
    const TunedParameters t = tune_parameters({sample.fibers(), {}, 0}, turns, h, search_for_effort(1), 0.1,
                                              std::nullopt, std::nullopt);
    EXPECT_EQ(t.search.retry_beam_width, search_for_effort(1).retry_beam_width);
    EXPECT_GT(t.search.retry_error_mm, 1e-4);  // 2.5 x a mean error of a few micrometres
    EXPECT_LT(t.search.retry_error_mm, 2e-2);
    // Without data there is nothing to set a threshold from: no retry.
    const TunedParameters none = tune_parameters({}, TurnStatistics(60, 0), h, search_for_effort(1), 0.1,
                                                 std::nullopt, std::nullopt);
    EXPECT_EQ(none.search.retry_beam_width, 0u);
}

TEST(BlockKeepingStep, FinestStepAtWhichNoFiberNeedsAnotherBlock) {
    // Brute force over fine steps: at the returned step every fiber's
    // counted points (length / step + 3) fit the blocks it needs at the
    // default step (counted low: 0.1 % short, + 2), and 0.1 % finer some
    // fiber would not; a file of long fibers (many blocks each) keeps its step.
    constexpr std::uint32_t ppb = 60;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> len(20.0, 180.0);
    std::vector<float> lengths(200);
    for (float& l : lengths) l = float(len(rng));
    const double step = 6.5;
    auto blocks = [&](double l, double s, double spare) { return std::ceil((std::floor(l / s) + spare) / ppb); };
    const double finer = block_keeping_step(lengths, step, ppb);
    EXPECT_LT(finer, kBlockKeepingShrink * step);
    EXPECT_GT(finer, 0.0);
    bool tight = false;
    for (const float l : lengths) {
        const double at_default = blocks(l * (1 - 1e-3), step, 2);
        EXPECT_LE(blocks(l, finer, 3), at_default) << l;
        tight = tight || blocks(l, finer * 0.999, 3) > at_default;
    }
    EXPECT_TRUE(tight) << "a finer step would still fit: not the finest";
    // Fibers of many points: no finer step keeps them all in their blocks.
    std::vector<float> long_fibers(200);
    for (float& l : long_fibers) l = float(len(rng));
    EXPECT_EQ(block_keeping_step(long_fibers, 0.1, ppb), 0.1);
    EXPECT_EQ(block_keeping_step({}, 0.5, ppb), 0.5);
    // Short fibers of few points: no finer than a quarter of the step.
    const std::vector<float> short_fibers(10, 1.0f);
    EXPECT_EQ(block_keeping_step(short_fibers, 0.5, ppb), kBlockKeepingFinest * 0.5);
}
