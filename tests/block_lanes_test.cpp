// The encoder's searches with one block per SIMD lane: greedy
// (encode/greedy_blocks.hpp) and lookahead at depths 1 and 2
// (encode/lookahead_blocks.hpp: the first search and the length tails).
// At every level this CPU supports, the same codes and the same decoded
// points, bit for bit, as the scalar searches (search_codes,
// LookaheadSearch), on random walks, on the shared tractogram and on the
// lookup's edge cases; the level choice and its errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "encode/greedy_blocks.hpp"
#include "encode/lookahead_blocks.hpp"
#include "encode/nearest_code_lut.hpp"
#include "core/vec_math.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/error.hpp"
#include "cli_runner.hpp"
#include "fiblet/compress.hpp"
#include "test_util.hpp"

using namespace fiblet;
using detail::SimdLevel;
using detail::operator+;
using detail::operator-;
using detail::operator*;

namespace {

// Forces a level for the scope, then returns to the default.
struct ForcedLevel {
    explicit ForcedLevel(SimdLevel l) { detail::force_simd_level(l); }
    ~ForcedLevel() { detail::force_simd_level(std::nullopt); }
};

// A batch's inputs in the encoder's layout: block j's start point at
// j * stride, its targets from j * stride + 1.
struct Blocks {
    std::size_t m = 0, stride = 0;
    std::vector<Frame> frames;
    std::vector<Vec3f> points;  // start point, then targets
    std::size_t last = 0;  // the last block's m when shorter (0: m)
    std::size_t count() const { return frames.size(); }
    std::size_t last_m() const { return last ? last : m; }
};

struct Result {
    std::vector<std::uint8_t> codes;
    std::vector<Vec3f> decoded;
};

// Which search: greedy aiming (depth 0) or the lookahead of depth 1 or 2
// with the aim's rival or four (the first search: 1 and the aim's; the
// length tails: 2 and the aim's; the retry: 2 and four).
struct Search {
    std::size_t depth = 0;
    detail::LookaheadRivals rivals = detail::LookaheadRivals::aim;
    bool greedy() const { return depth == 0; }
};
constexpr Search kSearches[] = {{0}, {1}, {2}, {1, detail::LookaheadRivals::four}, {2, detail::LookaheadRivals::four}};
std::string name_of(Search s) {
    if (s.greedy()) return "greedy";
    return "lookahead depth " + std::to_string(s.depth) +
           (s.rivals == detail::LookaheadRivals::aim ? ", the aim's rival" : ", four rivals");
}

Result run_level(const detail::Codebook8& cb, float step, const Blocks& in, SimdLevel level, Search search) {
    Result r;
    const std::size_t code_stride = in.m + 5;  // unlike the points' stride, as in the encoder
    r.codes.assign(in.count() * code_stride, 0xAA);
    r.decoded.assign(in.points.size(), Vec3f{-7, -7, -7});
    const detail::GreedyBatch batch{in.frames.data(), in.points.data(), in.points.data() + 1, r.decoded.data() + 1,
                                    in.stride, r.codes.data(), code_stride, in.count(), in.m, in.last_m()};
    if (search.greedy()) detail::greedy_blocks(cb, step, batch, level);
    else detail::lookahead_blocks(cb, step, search.depth, search.rivals, batch, level);
    return r;
}

// search_codes or LookaheadSearch, block by block, into the same layout.
Result run_reference(const detail::Codebook8& cb, float step, const Blocks& in, Search search) {
    Result r;
    const std::size_t code_stride = in.m + 5;
    r.codes.assign(in.count() * code_stride, 0xAA);
    r.decoded.assign(in.points.size(), Vec3f{-7, -7, -7});
    for (std::size_t j = 0; j < in.count(); ++j) {
        const std::size_t at = j * in.stride;
        const std::span<const Vec3f> targets(&in.points[at + 1], j + 1 == in.count() ? in.last_m() : in.m);
        if (search.greedy())
            detail::search_codes(cb, detail::SearchParams{1, 1}, in.frames[j], in.points[at], step, targets,
                                 &r.codes[j * code_stride], &r.decoded[at + 1]);
        else
            detail::LookaheadSearch<detail::Codebook8>(cb, step, search.depth, search.rivals)
                .run(in.frames[j], in.points[at], targets, &r.codes[j * code_stride], &r.decoded[at + 1]);
    }
    return r;
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a) && std::isnan(b)); }

// Every supported level against the reference: no code and no point differs.
void expect_same_at_every_level(const detail::Codebook8& cb, float step, const Blocks& in, const std::string& what,
                                Search search) {
    const Result ref = run_reference(cb, step, in, search);
    for (SimdLevel level : detail::supported_simd_levels()) {
        const Result got = run_level(cb, step, in, level, search);
        std::size_t bad_codes = 0, bad_points = 0, first = SIZE_MAX;
        for (std::size_t i = 0; i < ref.codes.size(); ++i)
            if (ref.codes[i] != got.codes[i]) ++bad_codes, first = std::min(first, i);
        for (std::size_t i = 0; i < ref.decoded.size(); ++i) {
            const Vec3f a = ref.decoded[i], b = got.decoded[i];
            if (!same_bits(a.x, b.x) || !same_bits(a.y, b.y) || !same_bits(a.z, b.z)) ++bad_points;
        }
        EXPECT_EQ(bad_codes, 0u) << name_of(search) << ", " << what << ", level " << detail::simd_level_name(level) << ", first code " << first;
        EXPECT_EQ(bad_points, 0u) << name_of(search) << ", " << what << ", level " << detail::simd_level_name(level);
    }
}

// Every search.
void expect_same_at_every_level(const detail::Codebook8& cb, float step, const Blocks& in, const std::string& what) {
    for (Search search : kSearches)
        expect_same_at_every_level(cb, step, in, what, search);
}

Vec3f unit(Vec3f v) { return detail::normalize(v); }

// `count` blocks of m targets: walks of spacing `spacing` turning up to
// `turn` (about the axis' angle per step) with jitter, from random starts
// and frames around the centre of the unit box.
Blocks random_walks(std::size_t count, std::size_t m, float spacing, double turn, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1, 1);
    Blocks b;
    b.m = m, b.stride = m + 3;
    b.points.assign(count * b.stride, Vec3f{});
    for (std::size_t j = 0; j < count; ++j) {
        Vec3f p{0.5f + 0.3f * u(rng), 0.5f + 0.3f * u(rng), 0.5f + 0.3f * u(rng)};
        Vec3f d = unit({u(rng), u(rng), u(rng)});
        b.frames.push_back(frame_from_axis(unit({d.x + 0.3f * u(rng), d.y + 0.3f * u(rng), d.z + 0.3f * u(rng)})));
        b.points[j * b.stride] = p;
        for (std::size_t k = 0; k < m; ++k) {
            d = unit({d.x + float(turn) * u(rng), d.y + float(turn) * u(rng), d.z + float(turn) * u(rng)});
            p = p + spacing * d;
            b.points[j * b.stride + 1 + k] = p + (0.05f * spacing) * Vec3f{u(rng), u(rng), u(rng)};
        }
    }
    return b;
}

}  // namespace

TEST(BlockLanes, LevelNamesAndChoice) {
    for (SimdLevel l : {SimdLevel::scalar, SimdLevel::sse4, SimdLevel::avx2, SimdLevel::avx512})
        EXPECT_EQ(detail::parse_simd_level(detail::simd_level_name(l)), l);
    EXPECT_EQ(detail::parse_simd_level("avx"), std::nullopt);
    EXPECT_EQ(detail::parse_simd_level(""), std::nullopt);
    EXPECT_TRUE(detail::simd_level_supported(SimdLevel::scalar));
    const auto levels = detail::supported_simd_levels();
    ASSERT_FALSE(levels.empty());
    EXPECT_EQ(levels.front(), SimdLevel::scalar);
    for (SimdLevel l : levels) {
        ForcedLevel forced(l);
        EXPECT_EQ(detail::simd_level(), l);
    }
    for (SimdLevel l : {SimdLevel::sse4, SimdLevel::avx2, SimdLevel::avx512})
        if (!detail::simd_level_supported(l)) {
            EXPECT_EQ(test::error_of([&] { detail::force_simd_level(l); }), Errc::invalid_argument);
        }
    // Which levels this machine ran: the log says, since a level it lacks is not tested.
    std::string names;
    for (SimdLevel l : levels) names += std::string(" ") + detail::simd_level_name(l);
    std::cout << "[ levels   ]" << names << "\n";
}

TEST(BlockLanes, RandomWalksMatchTheScalarSearchAtEveryLevel) {
    // Ratios: narrow to wide caps, and 1.2 (no lookup table: the scalar path at every level).
    for (float ratio : {0.01f, 0.0968f, 0.3f, 0.95f, 1.2f}) {
        const DirectionTable table(ratio);
        const detail::NearestCodeLut lut(table);
        const detail::Codebook8 cb{table, lut};
        // Steps from a tenth of the quantum to a twentieth of the box; the
        // targets' spacing a little off the step, turns gentle to sharp.
        unsigned seed = 1;
        for (float step : {2e-6f, 1.25e-3f, 1e-2f, 5e-2f})
            for (double turn : {0.05, 0.3, 1.5}) {
                const Blocks b = random_walks(37, 58, step * (seed % 2 ? 1.07f : 0.93f), turn, seed);
                expect_same_at_every_level(cb, step, b, "ratio " + std::to_string(ratio) + " step " +
                                                            std::to_string(step) + " turn " + std::to_string(turn));
                ++seed;
            }
    }
}

TEST(BlockLanes, AnyNumberOfBlocksAndAShorterLastBlock) {
    const DirectionTable table(0.0968f);
    const detail::NearestCodeLut lut(table);
    const detail::Codebook8 cb{table, lut};
    unsigned seed = 100;
    for (std::size_t count = 1; count <= 40; ++count)
        for (std::size_t last : {0, 1, 7, 57}) {
            Blocks b = random_walks(count, 58, 1.25e-3f, 0.3, seed++);
            b.last = last;
            // The points end with the last block's last target: nothing past it is read.
            b.points.resize((count - 1) * b.stride + 1 + b.last_m());
            b.points.shrink_to_fit();
            expect_same_at_every_level(cb, 1.25e-3f, b, std::to_string(count) + " blocks, last m " + std::to_string(last));
        }
}

TEST(BlockLanes, SharedTractogramBlocksMatchTheScalarSearchAtEveryLevel) {
    const std::string path = test::shared_data("small-ifod1.tck");
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "no shared data: " << path;
    const auto fibers = test::read_tck_fibers(path);
    ASSERT_FALSE(fibers.empty());
    // The encoder's normalization: a box around every point, the step 0.1 mm.
    Vec3f lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
    for (const auto& f : fibers)
        for (const Vec3f& p : f)
            lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)},
            hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    const float scaling = 1.01f * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    auto normalized = [&](Vec3f p) {
        return Vec3f{(p.x - lo.x) / scaling, (p.y - lo.y) / scaling, (p.z - lo.z) / scaling};
    };
    const float step = 0.1f / scaling;
    // Blocks of 60 points (58 codes) cut from the fibers, their first frame along their first segment.
    Blocks b;
    b.m = 58, b.stride = 59;
    for (const auto& f : fibers)
        for (std::size_t i0 = 0; i0 + 60 <= f.size(); i0 += 60) {
            b.frames.push_back(frame_from_axis(unit(normalized(f[i0 + 1]) - normalized(f[i0]))));
            for (std::size_t k = 1; k < 60; ++k) b.points.push_back(normalized(f[i0 + k]));
        }
    ASSERT_GT(b.count(), 1000u);
    for (float ratio : {0.0968f, 0.1458f}) {
        const DirectionTable table(ratio);
        const detail::NearestCodeLut lut(table);
        expect_same_at_every_level(detail::Codebook8{table, lut}, step, b, "small-ifod1, ratio " + std::to_string(ratio));
    }
}

TEST(BlockLanes, EncoderWritesTheSameBlocksAtEveryLevel) {
    const std::string path = test::shared_data("small-ifod1.tck");
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "no shared data: " << path;
    auto fibers = test::read_tck_fibers(path);
    fibers.resize(std::min<std::size_t>(fibers.size(), 500));
    FftHeader h;
    h.scaling = 200;
    h.offset = {0, 0, 0};
    h.ratio = 0.0968f;
    h.step = float(0.1 / 200);
    // Greedy (effort 0) and the default's lookahead with its retry and length tails.
    for (int effort : {0, kDefaultEffort}) {
        SearchOptions search = search_for_effort(effort);
        if (search.retry_beam_width > 0) search.retry_error_mm = 0.004;
        const FiberEncoder encoder = FiberEncoder(h, search).with_length_feedback(1.0f, true);
        // One fiber at a time, or 13 together (encode_fibers: the length
        // tails' searches of many fibers in SIMD lanes).
        auto encode_all = [&](SimdLevel level, std::vector<Vec3f>& decoded, std::size_t together) {
            ForcedLevel forced(level);
            std::vector<std::uint8_t> out;
            const std::vector<std::span<const Vec3f>> spans(fibers.begin(), fibers.end());
            for (std::size_t i = 0; i < fibers.size(); i += together)
                encoder.encode_fibers(std::span(spans).subspan(i, std::min(together, fibers.size() - i)), std::uint32_t(i),
                                      out, &decoded);
            return out;
        };
        std::vector<Vec3f> ref_decoded;
        const auto ref = encode_all(SimdLevel::scalar, ref_decoded, 1);
        for (SimdLevel level : detail::supported_simd_levels()) {
            std::vector<Vec3f> decoded;
            const auto got = encode_all(level, decoded, 13);
            EXPECT_TRUE(got == ref) << "effort " << effort << ", " << detail::simd_level_name(level);
            ASSERT_EQ(decoded.size(), ref_decoded.size());
            EXPECT_EQ(std::memcmp(decoded.data(), ref_decoded.data(), decoded.size() * sizeof(Vec3f)), 0)
                << "effort " << effort << ", " << detail::simd_level_name(level);
        }
    }
}

TEST(BlockLanes, EdgeCasesMatchTheScalarSearchAtEveryLevel) {
    const DirectionTable table(0.0968f);
    const detail::NearestCodeLut lut(table);
    const detail::Codebook8 cb{table, lut};
    ASSERT_TRUE(lut.usable());
    const Frame identity{{Vec3f{1, 0, 0}, Vec3f{0, 1, 0}, Vec3f{0, 0, 1}}};
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1, 1);
    const std::size_t m = 20, count = 35;
    auto blocks = [&](auto target_of) {
        Blocks b;
        b.m = m, b.stride = m + 1;
        b.points.assign(count * b.stride, Vec3f{});
        for (std::size_t j = 0; j < count; ++j) {
            b.frames.push_back(j % 2 ? identity : frame_from_axis(unit({u(rng), u(rng), u(rng)})));
            const Vec3f p{0.5f, 0.25f, 0.75f};
            b.points[j * b.stride] = p;
            for (std::size_t k = 0; k < m; ++k) b.points[j * b.stride + 1 + k] = target_of(j, k, p);
        }
        return b;
    };
    // The first target straight ahead, on the block's start point (zero
    // vector) or straight behind, with the identity frame: zero lateral,
    // in the cap, the zero code and the back code; then random targets, many behind.
    const Blocks zero_lateral = blocks([&](std::size_t j, std::size_t k, Vec3f p) {
        if (k == 0) return Vec3f{p.x + float(int(j % 3) - 1) * 0.01f, p.y, p.z};
        return p + 0.02f * Vec3f{u(rng), u(rng), u(rng)};
    });
    for (float step : {0.0f, 1e-3f, 0.01f}) expect_same_at_every_level(cb, step, zero_lateral, "zero lateral");
    // Every target behind the start, far: the walk turns around at the cap's rim.
    const Blocks behind = blocks([&](std::size_t, std::size_t k, Vec3f p) {
        return p + Vec3f{-0.3f - 0.01f * float(k), 0.001f * u(rng), 0.001f * u(rng)};
    });
    for (float step : {1e-4f, 1e-2f}) expect_same_at_every_level(cb, step, behind, "behind");
    // All targets on one point: the walk passes it and aims back.
    const Blocks one_point = blocks([&](std::size_t, std::size_t, Vec3f p) { return p + Vec3f{0.003f, 0.0f, 0.0f}; });
    for (float step : {1e-3f, 1e-2f}) expect_same_at_every_level(cb, step, one_point, "one point");
    // Huge steps and targets: squares overflow to inf (the cap test on
    // inf <= inf, u = y / x far out of int range, 0 * inf = NaN in the rim
    // branch), which the cell clamp must treat as the scalar code does.
    const Blocks far = blocks([&](std::size_t j, std::size_t, Vec3f p) {
        const float scale = j % 3 == 0 ? 1e20f : (j % 3 == 1 ? 1e30f : 1.0f);
        return p + scale * Vec3f{u(rng), u(rng), u(rng)};
    });
    for (float step : {1.0f, 1e3f, 1e18f, 1e30f, 3e38f}) expect_same_at_every_level(cb, step, far, "huge");
    // Along the axis at 1e20, across at 1e30 (first step, identity frame):
    // both squares overflow, the cap test passes on inf <= inf and
    // u = y / x = 1e10 is out of int range, where the scalar cell() gives 0.
    const Blocks overflow = blocks([&](std::size_t, std::size_t k, Vec3f p) {
        return p + Vec3f{1e20f * float(k + 1), 1e30f * u(rng), 1e29f * u(rng)};
    });
    for (float step : {1e-3f, 1e25f}) expect_same_at_every_level(cb, step, overflow, "overflowing squares");
    // Tiny steps near the denormals.
    const Blocks near = blocks([&](std::size_t, std::size_t k, Vec3f p) {
        return p + float(k + 1) * 1e-38f * Vec3f{1.0f, u(rng), u(rng)};
    });
    for (float step : {1e-38f, 1e-44f}) expect_same_at_every_level(cb, step, near, "tiny");
}

// compress says which level its search ran at (--json "simd"), writes the
// same bytes at every level, and refuses an unknown FIBLET_SIMD before any work.
TEST(BlockLanes, CompressReportsItsLevelAndTheSameBytesAtEach) {
    test::TempDir dir;
    const std::string tck = test::shared_data("small-ifod1.tck");
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    CompressOptions o;
    o.overwrite = true;
    o.threads = 1;
    for (int effort : {0, kDefaultEffort}) {
        o.search = search_for_effort(effort);
        std::string first;
        for (const SimdLevel level : detail::supported_simd_levels()) {
            SCOPED_TRACE(std::string("effort ") + std::to_string(effort) + ", " + detail::simd_level_name(level));
            CompressReport r;
            {
                const ForcedLevel forced(level);
                r = compress_file(tck, dir.file("x.fft"), o);
            }
            EXPECT_EQ(r.simd, detail::simd_level_name(level));
            const std::string bytes = test::read_file(dir.file("x.fft"));
            if (first.empty()) first = bytes;
            EXPECT_TRUE(bytes == first);
        }
    }
    const auto json = test::run_cli("compress -q -f --json " + tck + " -o " + dir.file("y.fft"), "FIBLET_SIMD=scalar");
    EXPECT_NE(json.output.find("\"simd\": \"scalar\""), std::string::npos) << json.output;
    const auto bad = test::run_cli("compress -q -f " + tck + " -o " + dir.file("z.fft"), "FIBLET_SIMD=bogus");
    EXPECT_EQ(bad.status, 2) << bad.output;
    EXPECT_NE(bad.output.find("FIBLET_SIMD=bogus"), std::string::npos) << bad.output;
}
