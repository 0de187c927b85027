// The blocks' starts four at a time (encode/anchor_conditioning.hpp,
// decoder_starts4) against decoder_starts and start_divergence one block
// at a time, bit for bit: random anchors, first segments near the helper
// vector ±C (both sides of the fallback's threshold, in float and in
// double), coinciding anchors and the words' extremes, with the AVX2 loops
// on and off.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "encode/anchor_conditioning.hpp"
#include "fiblet/direction_code.hpp"
#include "scoped_simd_loops.hpp"

namespace fiblet::detail {
namespace {

std::uint32_t clamp_word(double v) { return std::uint32_t(std::clamp(std::lround(v), 0L, 65535L)); }

// Anchor words: the second anchor `length` quanta from the first along
// `dir` (plus `jitter` quanta per axis), rounded.
AnchorWords along(std::array<std::uint32_t, 3> a0, const double dir[3], double length, const double jitter[3]) {
    AnchorWords w{a0, {}};
    for (int k = 0; k < 3; ++k) w.a1[k] = clamp_word(double(a0[k]) + length * dir[k] + jitter[k]);
    return w;
}

std::vector<AnchorWords> test_words() {
    std::mt19937 rng(7);
    std::uniform_int_distribution<std::uint32_t> word(0, 65535), near_middle(20000, 45000);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), length(1.0, 400.0);
    std::vector<AnchorWords> out;
    for (int i = 0; i < 400; ++i) out.push_back({{word(rng), word(rng), word(rng)}, {word(rng), word(rng), word(rng)}});
    // First segments along ±C, a few quanta off it: the fallback's cone.
    const double helper[3] = {kFrameHelper[0], kFrameHelper[1], kFrameHelper[2]};
    for (int i = 0; i < 400; ++i) {
        const double sign = i % 2 ? 1.0 : -1.0, dir[3] = {sign * helper[0], sign * helper[1], sign * helper[2]};
        const double jitter[3] = {0.01 * (i % 7) * unit(rng), 0.01 * (i % 5) * unit(rng), 0.01 * (i % 3) * unit(rng)};
        out.push_back(along({near_middle(rng), near_middle(rng), near_middle(rng)}, dir, length(rng), jitter));
    }
    const std::array<std::uint32_t, 3> corner{0, 65535, 0};
    out.push_back({corner, corner});  // coinciding anchors: the +x axis
    out.push_back({{0, 0, 0}, {65535, 65535, 65535}});
    out.push_back({{65535, 65535, 65535}, {0, 0, 0}});
    out.push_back({{100, 100, 100}, {101, 100, 100}});  // one quantum: the +x axis again
    return out;
}

void expect_same(const DecoderStarts& got, const DecoderStarts& want, std::size_t i) {
    EXPECT_EQ(got.words.a0, want.words.a0) << i;
    EXPECT_EQ(got.words.a1, want.words.a1) << i;
    for (const auto& [g, e] : {std::pair{got.a0, want.a0}, std::pair{got.a1, want.a1}}) {
        EXPECT_EQ(g.x, e.x) << i;
        EXPECT_EQ(g.y, e.y) << i;
        EXPECT_EQ(g.z, e.z) << i;
    }
    for (const auto& [g, e] : {std::pair{got.exact0, want.exact0}, std::pair{got.exact1, want.exact1}}) {
        EXPECT_EQ(g.x, e.x) << i;
        EXPECT_EQ(g.y, e.y) << i;
        EXPECT_EQ(g.z, e.z) << i;
    }
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(got.frame.c[c].x, want.frame.c[c].x) << i << " column " << c;
        EXPECT_EQ(got.frame.c[c].y, want.frame.c[c].y) << i << " column " << c;
        EXPECT_EQ(got.frame.c[c].z, want.frame.c[c].z) << i << " column " << c;
        EXPECT_EQ(got.exact_frame.c[c].x, want.exact_frame.c[c].x) << i << " column " << c;
        EXPECT_EQ(got.exact_frame.c[c].y, want.exact_frame.c[c].y) << i << " column " << c;
        EXPECT_EQ(got.exact_frame.c[c].z, want.exact_frame.c[c].z) << i << " column " << c;
    }
    EXPECT_EQ(got.divergence, want.divergence) << i;
    EXPECT_EQ(got.fallback, want.fallback) << i;
}

// A block's start from its words, the scalar way (decoder_starts, start_divergence).
DecoderStarts started(const AnchorWords& w, double reach) {
    DecoderStarts s = decoder_starts(w);
    s.divergence = start_divergence(s, reach);
    return s;
}

TEST(AnchorConditioning, FourStartsAtOnceAreTheScalarStarts) {
    const std::vector<AnchorWords> words = test_words();
    std::size_t fallbacks = 0;
    for (const bool simd : {true, false}) {
        const test::ScopedSimdLoops loops(simd);
        for (std::size_t i = 0; i + 4 <= words.size(); i += 4) {
            const double reach[4] = {0.0, 1e-3, 0.0037 * double(i % 60), 2.5};
            DecoderStarts four[4];
            decoder_starts4(&words[i], reach, four);
            for (std::size_t j = 0; j < 4; ++j) {
                const DecoderStarts one = started(words[i + j], reach[j]);
                expect_same(four[j], one, i + j);
                fallbacks += simd && one.fallback;
            }
        }
    }
    EXPECT_GT(fallbacks, 10u);  // the words near ±C reach the fallback's cone
}

// condition_anchors from the nearest rounding's start: that start where it
// needs no search; else a start whose fields are its own words' (not the
// nearest's left over), never the fallback's, and on a rounding within a
// few quanta of the nearest.
TEST(AnchorConditioning, TheSearchStartsFromTheNearestRoundingsStart) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0.2, 0.8), small(-2e-3, 2e-3);
    const double helper[3] = {kFrameHelper[0], kFrameHelper[1], kFrameHelper[2]};
    std::size_t searched = 0, fallbacks = 0;
    for (int i = 0; i < 300; ++i) {
        const Vec3d n0{u(rng), u(rng), u(rng)};
        // Random first segments, short ones near C, and long ones along C
        // (their rounding stays in the fallback's cone).
        const int kind = i % 3;
        const double along_c = kind == 0 ? 0.0 : kind == 1 ? 2e-3 : 0.1, noise = kind == 2 ? 0.0 : 1.0;
        const Vec3d n1{n0.x + along_c * helper[0] + noise * small(rng),
                       n0.y + along_c * helper[1] + noise * small(rng) * (kind == 0),
                       n0.z + along_c * helper[2] + noise * small(rng) * (kind == 0)};
        const double reach = 0.01, threshold = 0.5 / 65535.0;
        const DecoderStarts nearest = started(nearest_words(n0, n1), reach);
        const DecoderStarts got = condition_anchors(n0, n1, reach, threshold, nearest);
        if (!nearest.fallback && !(nearest.divergence > threshold)) {
            expect_same(got, nearest, i);
            continue;
        }
        ++searched, fallbacks += nearest.fallback;
        expect_same(got, started(got.words, reach), i);
        EXPECT_FALSE(got.fallback) << i;
        for (int k = 0; k < 3; ++k) {
            EXPECT_LE(std::abs(std::int64_t(got.words.a0[k]) - std::int64_t(nearest.words.a0[k])), 1) << i;
            EXPECT_LE(std::abs(std::int64_t(got.words.a1[k]) - std::int64_t(nearest.words.a1[k])), 4) << i;
        }
    }
    EXPECT_GT(searched, 0u);
    EXPECT_GT(fallbacks, 0u);
}

}  // namespace
}  // namespace fiblet::detail
