// The encoder's code search: the fast nearest-code lookup against brute
// force, the beam against greedy aiming, the retry of the worst blocks, and
// the effort presets.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <random>

#include "encode/code_search.hpp"
#include "encode/nearest_code_lut.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/error.hpp"
#include "scoped_simd_loops.hpp"

using namespace fiblet;

namespace {

double angle(Vec3f a, Vec3f b) {
    const double c = (double(a.x) * b.x + double(a.y) * b.y + double(a.z) * b.z) /
                     std::sqrt((double(a.x) * a.x + double(a.y) * a.y + double(a.z) * a.z) *
                               (double(b.x) * b.x + double(b.y) * b.y + double(b.z) * b.z));
    return std::acos(std::clamp(c, -1.0, 1.0));
}

double nearest_angle(const DirectionTable& t, Vec3f d) {
    double best = M_PI;
    for (int c = 0; c < 256; ++c) best = std::min(best, angle(t.direction(std::uint8_t(c)), d));
    return best;
}

// Fibers of 0.1 mm steps turning up to 12 degrees per step, inside a 40 mm box.
std::vector<std::vector<Vec3f>> walks(int count, int points, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<std::vector<Vec3f>> out;
    for (int i = 0; i < count; ++i) {
        double p[3] = {20 * u(rng), 20 * u(rng), 20 * u(rng)}, d[3] = {u(rng), u(rng), u(rng)};
        std::vector<Vec3f> f;
        for (int k = 0; k < points; ++k) {
            f.push_back({float(p[0]), float(p[1]), float(p[2])});
            const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (double& c : d) c /= n;
            for (double& c : d) c += 0.2 * u(rng);  // about 12 degrees at most
            const double m = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (int a = 0; a < 3; ++a) p[a] += 0.1 * d[a] / m;
        }
        out.push_back(f);
    }
    return out;
}

FftHeader header(float ratio) {
    FftHeader h;
    h.scaling = 80;
    h.offset = {0, 0, 0};
    h.ratio = ratio;
    h.step = float(0.1 / 80);
    return h;
}

// Per block: the largest distance between a decoded point and its input.
std::vector<double> block_max_errors(const FiberEncoder& e, const std::vector<Vec3f>& f, double* sum2 = nullptr) {
    std::vector<std::uint8_t> blocks;
    std::vector<Vec3f> decoded;
    e.encode(f, 0, blocks, &decoded);
    std::vector<double> out;
    for (std::size_t k = 0; k < f.size(); ++k) {
        if (k % e.header().points_per_block == 0) out.push_back(0);
        const double d2 = std::pow(double(decoded[k].x) - f[k].x, 2) + std::pow(double(decoded[k].y) - f[k].y, 2) +
                          std::pow(double(decoded[k].z) - f[k].z, 2);
        out.back() = std::max(out.back(), std::sqrt(d2));
        if (sum2) *sum2 += d2;
    }
    return out;
}

}  // namespace

TEST(NearestCodeLut, PicksACodeWithinTwoCellsOfTheNearest) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    for (float ratio : {0.01f, 0.0968f, 0.1458f, 0.5f, 0.95f}) {
        const DirectionTable t(ratio);
        const detail::NearestCodeLut lut(t);
        ASSERT_TRUE(lut.usable());
        const double cap = std::acos(1.0 - ratio);
        // Two cells' half-diagonals, in gnomonic units (an upper bound on the angle).
        const double slack = 2 * std::sqrt(2.0) * std::tan(cap) / detail::NearestCodeLut::kGrid + 1e-6;
        for (int i = 0; i < 20000; ++i) {
            // Directions in the cap, and (one in four) anywhere on the sphere.
            Vec3f d;
            if (i % 4 == 3) {
                d = {float(u(rng)), float(u(rng)), float(u(rng))};
            } else {
                const double polar = cap * std::sqrt(std::fabs(u(rng))), az = M_PI * u(rng);
                const double len = 0.01 + std::fabs(u(rng));  // any length
                d = {float(len * std::cos(polar)), float(len * std::sin(polar) * std::cos(az)),
                     float(len * std::sin(polar) * std::sin(az))};
            }
            const std::uint8_t c = lut(d);
            if (i % 4 == 3 && angle(d, {1, 0, 0}) > cap) {
                // Outside the cap: as good as the nearest code of the rim point in d's azimuth.
                const double lateral = std::hypot(double(d.y), double(d.z));
                const Vec3f rim{float(std::cos(cap)), float(std::sin(cap) * d.y / lateral), float(std::sin(cap) * d.z / lateral)};
                EXPECT_LE(angle(t.direction(c), d), angle(d, rim) + nearest_angle(t, rim) + slack) << ratio;
            } else if (i % 4 != 3) {
                EXPECT_LE(angle(t.direction(c), d), nearest_angle(t, d) + slack) << "ratio " << ratio;
            }
        }
    }
}

TEST(NearestCodeLut, RivalIsTheGridNeighbourNearestTheAim) {
    std::mt19937 rng(6);
    std::uniform_real_distribution<double> u(-1, 1);
    for (float ratio : {0.01f, 0.0968f, 0.5f, 0.95f}) {
        const DirectionTable t(ratio);
        const detail::NearestCodeLut lut(t);
        const double cap = std::acos(1.0 - ratio);
        const double slack = 2 * std::sqrt(2.0) * std::tan(cap) / detail::NearestCodeLut::kGrid + 1e-6;
        for (int i = 0; i < 20000; ++i) {
            const double polar = cap * std::sqrt(std::fabs(u(rng))), az = M_PI * u(rng);
            const Vec3f d{float(std::cos(polar)), float(std::sin(polar) * std::cos(az)), float(std::sin(polar) * std::sin(az))};
            const auto a = lut.aim(d);
            ASSERT_EQ(a.code, lut(d));
            const int h = a.code >> 4, l = a.code & 15, rh = a.rival >> 4, rl = a.rival & 15;
            ASSERT_EQ(std::abs(rh - h) + std::abs(rl - l), 1) << int(a.code) << " " << int(a.rival);
            // Nearest in angle among the code's one-level neighbours, but for
            // directions within a cell of a tie.
            double nearest = INFINITY;
            for (const auto& [dh, dl] : {std::pair{-1, 0}, {0, -1}, {0, 1}, {1, 0}})
                if (h + dh >= 0 && h + dh < 16 && l + dl >= 0 && l + dl < 16)
                    nearest = std::min(nearest, angle(t.direction(std::uint8_t((h + dh) << 4 | (l + dl))), d));
            EXPECT_LE(angle(t.direction(a.rival), d), nearest + slack) << "ratio " << ratio;
            // Without the table (caps of a half sphere): the nearest, to the
            // resolution of a float dot product (~1e-7 / angle: 1e-5 rad at
            // the smallest cap's 0.01 rad).
            EXPECT_NEAR(angle(t.direction(lut.rival(a.code, d)), d), nearest, 2e-5);
        }
    }
}

TEST(NearestCodeLut, NotUsedForCapsReachingTheHalfSphere) {
    EXPECT_FALSE(detail::NearestCodeLut(DirectionTable(1.0f)).usable());
    EXPECT_FALSE(detail::NearestCodeLut(DirectionTable(1.7f)).usable());
}

// The encoder's AVX2 loops (the targets' normalization, the length
// terms, the error maxima) against their scalar twins: the same blocks and
// predicted points, greedy and at the default effort (lookahead, retry,
// length tails), fibers of every length up to a few blocks.
TEST(CodeSearch, EncoderWritesTheSameBlocksWithAndWithoutTheAvx2Loops) {
    FftHeader h = header(0.0968f);
    h.offset = {1.5f, -2.25f, 3.75f};  // each axis its own: the vector loop rotates them
    for (const SearchOptions& search : {SearchOptions{1, 1, 0, 1, 0}, search_for_effort(1)}) {
        const FiberEncoder e(h, search);
        for (int points : {1, 2, 3, 4, 5, 7, 61, 62, 125, 250}) {
            for (const auto& f : walks(3, points, unsigned(points))) {
                std::vector<std::uint8_t> blocks[2];
                std::vector<Vec3f> predicted[2];
                for (int avx2 = 0; avx2 < 2; ++avx2) {
                    const test::ScopedSimdLoops loops(avx2 == 1);
                    e.encode(f, 3, blocks[avx2], &predicted[avx2]);
                }
                EXPECT_EQ(blocks[0], blocks[1]) << points << " points";
                ASSERT_EQ(predicted[0].size(), predicted[1].size());
                EXPECT_EQ(0, std::memcmp(predicted[0].data(), predicted[1].data(), predicted[0].size() * sizeof(Vec3f)))
                    << points << " points";
            }
        }
    }
}

TEST(CodeSearch, BeamLowersTheSquaredErrorOfGreedyAiming) {
    const auto fibers = walks(40, 300, 1);
    const FftHeader h = header(0.0968f);
    double greedy = 0, beam4 = 0, beam16 = 0;
    for (const auto& f : fibers) {
        block_max_errors(FiberEncoder(h, {1, 1, 0, 1, 0}), f, &greedy);
        block_max_errors(FiberEncoder(h, {4, 1, 0, 1, 0}), f, &beam4);
        block_max_errors(FiberEncoder(h, {16, 1, 0, 1, 0}), f, &beam16);
    }
    EXPECT_LT(beam4, 0.85 * greedy);
    EXPECT_LT(beam16, beam4);
}

TEST(CodeSearch, RetryNeverRaisesABlocksMaxErrorAndLowersTheWorst) {
    const auto fibers = walks(40, 300, 2);
    const FftHeader h = header(0.0968f);
    const FiberEncoder greedy(h, {1, 1, 0, 1, 0});
    const FiberEncoder retry(h, {1, 1, 16, 1, 3e-3});  // blocks above 3 um are searched again
    double worst_greedy = 0, worst_retry = 0;
    int retried_better = 0;
    for (const auto& f : fibers) {
        const auto a = block_max_errors(greedy, f), b = block_max_errors(retry, f);
        ASSERT_EQ(a.size(), b.size());
        for (std::size_t i = 0; i < a.size(); ++i) {
            EXPECT_LE(b[i], a[i]);
            if (a[i] <= 3e-3) {
                EXPECT_EQ(b[i], a[i]);  // below the threshold: untouched
            }
            retried_better += b[i] < a[i];
            worst_greedy = std::max(worst_greedy, a[i]), worst_retry = std::max(worst_retry, b[i]);
        }
    }
    EXPECT_GT(retried_better, 0);
    EXPECT_LT(worst_retry, worst_greedy);
}

TEST(CodeSearch, EffortPresetsAreValidAndSearchMoreAsTheyGrow) {
    unsigned last_candidates = 0;
    for (int e = 0; e <= kMaxEffort; ++e) {
        const SearchOptions s = search_for_effort(e);
        EXPECT_NO_THROW(FiberEncoder(header(0.1f), s));
        const unsigned candidates = s.beam_width * (2 * s.radius + 1) * (2 * s.radius + 1);
        EXPECT_GE(candidates, last_candidates);
        last_candidates = candidates;
    }
    EXPECT_THROW(search_for_effort(-1), Error);
    EXPECT_THROW(search_for_effort(kMaxEffort + 1), Error);
    EXPECT_THROW(FiberEncoder(header(0.1f), {0, 1, 0, 1, 0}), Error);
    EXPECT_THROW(FiberEncoder(header(0.1f), {1, 4, 0, 1, 0}), Error);
}

TEST(CodeSearch, SixteenBitSearchDecodesToWhatTheEncoderPredicted) {
    FftHeader h = header(0.12f);
    h.version = kFft16Version;
    h.points_per_block = 126;
    const DecodeContext ctx(h);
    for (SearchOptions s : {SearchOptions{1, 1, 0, 1, 0}, SearchOptions{4, 1, 8, 1, 1e-9}}) {
        const FiberEncoder e(h, s);
        for (const auto& f : walks(5, 400, 3)) {
            std::vector<std::uint8_t> blocks;
            std::vector<Vec3f> predicted;
            e.encode(f, 7, blocks, &predicted);
            ASSERT_EQ(blocks.size(), e.block_count(f.size()) * std::size_t(h.block_bytes()));
            std::vector<float> xyz(3 * f.size());
            ASSERT_EQ(decode_blocks_scalar16(ctx, blocks.data(), blocks.size() / h.block_bytes(), xyz.data()), f.size());
            for (std::size_t k = 0; k < f.size(); ++k) EXPECT_EQ((Vec3f{xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]}), predicted[k]);
            EXPECT_EQ(BlockView16{blocks.data()}.fiber_id(), 7u);
        }
    }
}

namespace {

// The lookahead rule written plainly (no branch and bound, no kept
// continuation): the aimed code and its four nearest codes are followed by
// `depth` greedy steps to the block's end at most, each scored by the sum of
// its squared errors; the aimed code stands unless a rival tried after it,
// cheapest own error first, has a smaller sum.
std::vector<std::uint8_t> brute_force_lookahead(const detail::Codebook8& cb, Frame f, Vec3f p, float step,
                                                const std::vector<Vec3f>& t, std::size_t depth, bool four) {
    using namespace detail;
    auto error2 = [&](Vec3f local, unsigned c) {
        return std::max(0.0f, dot(local, local) + step * step - 2.0f * step * dot(cb.direction(c), local));
    };
    std::vector<std::uint8_t> codes;
    for (std::size_t k = 0; k < t.size(); ++k) {
        const Vec3f local = apply_transposed(f, t[k] - p);
        const unsigned aimed = cb.nearest(local);
        auto path_error2 = [&](unsigned c) {
            float e = error2(local, c);
            Frame g = compose(f, cb.frame(c));
            Vec3f q = p + step * g.c[0];
            for (std::size_t j = k + 1; j < std::min(t.size(), k + 1 + depth); ++j) {
                const Vec3f l = apply_transposed(g, t[j] - q);
                const unsigned a = cb.nearest(l);
                e += error2(l, a);
                g = compose(g, cb.frame(a));
                q = q + step * g.c[0];
            }
            return e;
        };
        // The rivals: the codes one level up or down on one grid axis (four),
        // or of those the one nearest the aim, as the lookup table gives it
        // (NearestCodeLut.RivalIsTheGridNeighbourNearestTheAim).
        std::vector<std::pair<float, unsigned>> rivals;  // (own error, code), in grid order
        const int h0 = int(aimed) / 16, l0 = int(aimed) % 16;
        for (int h = std::max(h0 - 1, 0); h <= std::min(h0 + 1, 15); ++h)
            for (int l = std::max(l0 - 1, 0); l <= std::min(l0 + 1, 15); ++l)
                if (std::abs(h - h0) + std::abs(l - l0) == 1 && (four || unsigned(h * 16 + l) == cb.aim(local).rival))
                    rivals.emplace_back(error2(local, unsigned(h * 16 + l)), unsigned(h * 16 + l));
        std::stable_sort(rivals.begin(), rivals.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
        unsigned code = aimed;
        if (k + 1 < t.size()) {
            float best = path_error2(aimed);
            for (const auto& [own, c] : rivals)
                if (const float e = path_error2(c); e < best) best = e, code = c;
        }
        codes.push_back(std::uint8_t(code));
        f = compose(f, cb.frame(code));
        p = p + step * f.c[0];
    }
    return codes;
}

}  // namespace

TEST(CodeSearch, LookaheadChoosesWhatThePlainRuleChooses) {
    using namespace detail;
    const FftHeader h = header(0.0968f);
    const DirectionTable table(h.ratio);
    const detail::NearestCodeLut lut(table);
    const detail::Codebook8 cb{table, lut};
    std::size_t points = 0, differ_from_greedy = 0;
    for (const auto& [depth, rivals] : {std::pair{1u, LookaheadRivals::aim}, {2u, LookaheadRivals::aim},
                                        {4u, LookaheadRivals::aim}, {1u, LookaheadRivals::four},
                                        {2u, LookaheadRivals::four}, {4u, LookaheadRivals::four}}) {
        const bool four = rivals == LookaheadRivals::four;
        detail::LookaheadSearch<detail::Codebook8> search(cb, h.step, depth, rivals);
        for (const auto& f : walks(20, 58, 4 + unsigned(depth))) {
            std::vector<Vec3f> t(f.size());
            for (std::size_t k = 0; k < f.size(); ++k) t[k] = {f[k].x / h.scaling + 0.5f, f[k].y / h.scaling + 0.5f, f[k].z / h.scaling + 0.5f};
            const Frame f0 = frame_from_axis(detail::normalize(t[1] - t[0]));
            const std::vector<Vec3f> targets(t.begin() + 2, t.end());
            std::vector<std::uint8_t> codes(targets.size()), greedy(targets.size());
            std::vector<Vec3f> decoded(targets.size());
            search.run(f0, t[1], targets, codes.data(), decoded.data());
            EXPECT_EQ(codes, brute_force_lookahead(cb, f0, t[1], h.step, targets, depth, four))
                << "depth " << depth << (four ? ", four rivals" : ", the aim's rival");
            detail::search_codes(cb, {1, 1}, f0, t[1], h.step, targets, greedy.data(), decoded.data());
            for (std::size_t k = 0; k < codes.size(); ++k) differ_from_greedy += codes[k] != greedy[k];
            points += codes.size();
        }
    }
    EXPECT_GT(differ_from_greedy, points / 50);  // the lookahead does change codes
}

TEST(CodeSearch, LookaheadLowersTheSquaredErrorOfGreedyAiming) {
    const auto fibers = walks(40, 300, 6);
    const FftHeader h = header(0.0968f);
    double greedy = 0, lookahead = 0;
    SearchOptions with_lookahead{1, 1, 0, 1, 0};
    with_lookahead.lookahead = 2;
    for (const auto& f : fibers) {
        block_max_errors(FiberEncoder(h, {1, 1, 0, 1, 0}), f, &greedy);
        block_max_errors(FiberEncoder(h, with_lookahead), f, &lookahead);
    }
    EXPECT_LT(lookahead, 0.9 * greedy);
    with_lookahead.lookahead = detail::kMaxLookahead + 1;
    EXPECT_THROW(FiberEncoder(h, with_lookahead), Error);
}

namespace {

// Codebook8 without its row frames and neighbour tables: search_codes then
// runs its generic beam on Frames, the reference for beam_search_rows.
struct PlainCodebook8 {
    using Code = std::uint8_t;
    const detail::Codebook8& cb;
    static constexpr int levels() { return 16; }
    Code nearest(Vec3f local) const { return cb.nearest(local); }
    const Frame& frame(unsigned c) const { return cb.frame(c); }
    const Vec3f& direction(unsigned c) const { return cb.direction(c); }
};

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST(CodeSearch, RowFramesComposeAndApplyBitForBitAsFrames) {
    using namespace detail;
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1, 1);
    const DirectionTable table(0.0968f);
    for (int i = 0; i < 2000; ++i) {
        const Frame f = frame_from_axis(normalize(Vec3f{u(rng), u(rng), u(rng)}));
        const Frame& l = table.frame(std::uint8_t(rng() % 256));
        const Vec3f v{100 * u(rng), 100 * u(rng), 100 * u(rng)};
        const Frame want = compose(f, l);
        const RowFrame got = compose(row_frame(f), row_frame(l));
        const Vec3f axis_got = vec3_of(axis(got));
        for (int r = 0; r < 3; ++r) {
            const Vec3f row = vec3_of(got.r[r]);
            const float* w[3] = {&want.c[0].x, &want.c[1].x, &want.c[2].x};
            EXPECT_TRUE(same_bits(row.x, w[0][r]) && same_bits(row.y, w[1][r]) && same_bits(row.z, w[2][r]));
        }
        EXPECT_TRUE(same_bits(axis_got.x, want.c[0].x) && same_bits(axis_got.y, want.c[0].y) && same_bits(axis_got.z, want.c[0].z));
        const Vec3f a = apply_transposed(f, v), b = vec3_of(apply_transposed(row_frame(f), f4_of(v)));
        EXPECT_TRUE(same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z));
    }
}

TEST(CodeSearch, BeamOnRowFramesChoosesWhatTheGenericBeamChooses) {
    using namespace detail;
    const FftHeader h = header(0.0968f);
    const DirectionTable table(h.ratio);
    const NearestCodeLut lut(table);
    const Codebook8 cb{table, lut};
    const PlainCodebook8 plain{cb};
    std::size_t compared = 0;
    for (unsigned width : {2u, 8u, 16u})
        for (bool robust : {false, true})
            for (const auto& f : walks(6, 58, 20 + width)) {
                std::vector<Vec3f> t(f.size()), alt;
                for (std::size_t k = 0; k < f.size(); ++k)
                    t[k] = {f[k].x / h.scaling + 0.5f, f[k].y / h.scaling + 0.5f, f[k].z / h.scaling + 0.5f};
                const Frame f0 = frame_from_axis(normalize(t[1] - t[0]));
                const std::vector<Vec3f> targets(t.begin() + 2, t.end());
                if (robust)  // the second decoder's targets: a small rotation away
                    for (const Vec3f& p : targets) alt.push_back({p.x + 1e-5f * (p.y - 0.5f), p.y - 1e-5f * (p.x - 0.5f), p.z});
                std::vector<std::uint8_t> got(targets.size()), want(targets.size());
                std::vector<Vec3f> got_points(targets.size()), want_points(targets.size());
                search_codes(cb, {width, 1}, f0, t[1], h.step, targets, got.data(), got_points.data(), alt);
                search_codes(plain, {width, 1}, f0, t[1], h.step, targets, want.data(), want_points.data(), alt);
                EXPECT_EQ(got, want) << "width " << width << (robust ? ", robust" : "");
                for (std::size_t k = 0; k < targets.size(); ++k)
                    EXPECT_TRUE(same_bits(got_points[k].x, want_points[k].x) && same_bits(got_points[k].y, want_points[k].y) &&
                                same_bits(got_points[k].z, want_points[k].z));
                compared += targets.size();
            }
    EXPECT_EQ(compared, 3u * 2u * 6u * 56u);
}
