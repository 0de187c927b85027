// Fibers end where their input does (the ENDS chunk, formats/fft-ends.md):
// endpoints and lengths of decoded fibers checked against the input .tck for
// fixed-step input with a short last segment, variable spacing from 0.01 to
// 10 mm, one- and two-point fibers, loops and a 10^5-point fiber; every
// decoder and selection path; what a reader ignoring the chunk sees.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "encode/fiber_end_encoder.hpp"
#include "fiblet/block_index.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fiber_ends.hpp"
#include "fiblet/fft_subset.hpp"
#include "fiblet/select.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

namespace fiblet {
namespace {

using Fiber = std::vector<Vec3f>;

double dist(Vec3f a, Vec3f b) {
    const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}

double length_of(const Fiber& f) {
    double l = 0;
    for (std::size_t i = 1; i < f.size(); ++i) l += dist(f[i - 1], f[i]);
    return l;
}

Fiber fiber_of(const Streamlines& s, std::size_t i) {
    Fiber f;
    for (std::uint64_t k = s.offsets[i]; k < s.offsets[i + 1]; ++k)
        f.push_back({s.xyz[3 * k], s.xyz[3 * k + 1], s.xyz[3 * k + 2]});
    return f;
}

// A smooth curve (a slow helix) sampled at the given arc-length increments.
Fiber helix(const std::vector<double>& increments, Vec3f origin = {0, 0, 0}, double radius = 15, double pitch = 0.3) {
    Fiber f;
    double s = 0;
    auto at = [&](double arc) {
        const double t = arc / radius;
        return Vec3f{float(origin.x + radius * std::cos(t)), float(origin.y + radius * std::sin(t)),
                     float(origin.z + pitch * arc)};
    };
    f.push_back(at(0));
    for (double d : increments) f.push_back(at(s += d));
    return f;
}

struct Encoded {
    CompressReport report;
    Streamlines decoded;
};

Encoded encode(const test::TempDir& dir, const std::vector<Fiber>& fibers, CompressOptions o = {}) {
    {
        TckWriter w(dir.file("in.tck"), {}, true);
        for (const Fiber& f : fibers) w.write(f);
        w.finish();
    }
    o.overwrite = true;
    Encoded e;
    e.report = compress_file(dir.file("in.tck"), dir.file("out.fft"), o);
    const FftFile file(dir.file("out.fft"));
    e.decoded = decode_fibers(file, 0, file.header().fibers);
    return e;
}

// Every fiber starts and ends within the recorded error of its input, and
// its length is the input's to well under one step.
void expect_ends_and_lengths(const std::vector<Fiber>& in, const Encoded& e, double length_tolerance_steps = 0.1) {
    ASSERT_EQ(e.decoded.size(), in.size());
    const double bound = double(e.report.header.max_error_mm) * (1 + 1e-6) + 1e-7;
    ASSERT_LT(bound, 0.5 * e.report.step_mm) << "the codec error itself is out of range";
    for (std::size_t i = 0; i < in.size(); ++i) {
        const Fiber d = fiber_of(e.decoded, i);
        if (in[i].empty()) {
            EXPECT_TRUE(d.empty());
            continue;
        }
        ASSERT_FALSE(d.empty()) << "fiber " << i;
        EXPECT_LE(dist(d.front(), in[i].front()), bound) << "start of fiber " << i;
        EXPECT_LE(dist(d.back(), in[i].back()), bound) << "end of fiber " << i << " (" << in[i].size() << " points)";
        EXPECT_LE(std::fabs(length_of(d) - length_of(in[i])), length_tolerance_steps * e.report.step_mm)
            << "length of fiber " << i;
    }
}

TEST(FiberEnds, FixedStepInputWithShortLastSegment) {
    test::TempDir dir;
    std::vector<Fiber> fibers;
    for (int k = 0; k < 12; ++k) {
        std::vector<double> inc(150 + 7 * k, 0.1);
        inc.push_back(0.01 + 0.008 * k);  // the tracker stopped mid-step
        fibers.push_back(helix(inc, {float(k), 0, 0}));
    }
    const Encoded e = encode(dir, fibers);
    EXPECT_TRUE(e.report.resampled);
    expect_ends_and_lengths(fibers, e);
}

TEST(FiberEnds, VariableSpacingFrom0_01To10Millimetres) {
    test::TempDir dir;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> log_spacing(std::log(0.01), std::log(10.0));
    std::vector<Fiber> fibers;
    for (int k = 0; k < 40; ++k) {
        std::vector<double> inc(5 + k % 30);
        for (double& d : inc) d = std::exp(log_spacing(rng));
        fibers.push_back(helix(inc, {0, float(k), 0}, 40));
    }
    CompressOptions o;
    o.step_mm = 0.5;  // the median of such spacings means little: fix the step
    const Encoded e = encode(dir, fibers, o);
    EXPECT_TRUE(e.report.resampled);
    // Chords of 0.5 mm cut the input's corners a little: lengths within a fifth of a step.
    expect_ends_and_lengths(fibers, e, 0.2);
}

TEST(FiberEnds, OneAndTwoPointFibers) {
    test::TempDir dir;
    std::vector<Fiber> fibers{{{1, 2, 3}},
                              {{0, 0, 0}, {0.03f, 0.01f, 0}},        // shorter than a step
                              {{0, 0, 0}, {3, 4, 0}},                // several steps, straight
                              {{5, 5, 5}, {5, 5, 5}},                // zero length
                              {},                                    // empty
                              helix(std::vector<double>(30, 0.25))};  // a regular one
    fibers.back().push_back({fibers.back().back().x + 0.02f, fibers.back().back().y, fibers.back().back().z});
    CompressOptions o;
    o.step_mm = 0.25;
    // The helix's segments (0.26 mm) are longer than the step: the chords cut its corners a little.
    expect_ends_and_lengths(fibers, encode(dir, fibers, o), 0.2);
}

TEST(FiberEnds, LoopsThatComeBackToTheirStart) {
    test::TempDir dir;
    std::vector<Fiber> fibers;
    for (int k = 0; k < 6; ++k) {
        const double r = 2.0 + k;
        Fiber f;
        const int n = 40 + 13 * k;
        for (int i = 0; i <= n; ++i) {  // one turn and a bit: the end passes the start
            const double t = 2 * M_PI * (1.07 * i / n);
            f.push_back({float(r * std::cos(t)), float(r * std::sin(t)), float(0.02 * i)});
        }
        fibers.push_back(f);
    }
    CompressOptions o;
    o.step_mm = 0.2;
    expect_ends_and_lengths(fibers, encode(dir, fibers, o), 0.2);
}

TEST(FiberEnds, AHundredThousandPointFiber) {
    test::TempDir dir;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> spacing(0.05, 0.15);
    std::vector<double> inc(100000 - 1);
    for (double& d : inc) d = spacing(rng);
    std::vector<Fiber> fibers{helix(inc, {0, 0, 0}, 30, 0.002)};  // 53 turns in a 60 mm box
    CompressOptions o;
    o.step_mm = 0.1;
    const Encoded e = encode(dir, fibers, o);
    ASSERT_GT(e.decoded.point_count(), 90000u);
    // 0.2 step of a 10 m fiber: 2 ppm, the float32 rounding of its points.
    expect_ends_and_lengths(fibers, e, 0.2);
}

// The last block of a resampled fiber holds 1, 2, 3 ... 60 points: the end is
// an anchor (1-2 points) or direction-coded and placed by the fraction.
TEST(FiberEnds, EveryLastBlockSize) {
    test::TempDir dir;
    std::vector<Fiber> fibers;
    for (int k = 1; k <= 125; ++k) {
        std::vector<double> inc(std::size_t(k), 0.1);
        inc.back() = 0.037;
        fibers.push_back(helix(inc, {0, 0, float(k)}));
    }
    const Encoded e = encode(dir, fibers);
    expect_ends_and_lengths(fibers, e);
}

// All decoders, the whole-file decode and the selection give the same ends.
TEST(FiberEnds, EveryDecodePathPlacesTheEnd) {
    test::TempDir dir;
    std::vector<Fiber> fibers;
    for (int k = 0; k < 30; ++k) {
        std::vector<double> inc(40 + 11 * k, 0.1);
        inc.back() = 0.02 + 0.002 * k;
        fibers.push_back(helix(inc, {float(k), 0, 0}));
    }
    const Encoded e = encode(dir, fibers);
    const FftFile file(dir.file("out.fft"));
    ASSERT_TRUE(file.end_fractions());
    const double bound = double(e.report.header.max_error_mm) * (1 + 1e-6) + 1e-6;
    auto check = [&](const Streamlines& s, const std::string& how) {
        ASSERT_EQ(s.size(), fibers.size()) << how;
        for (std::size_t i = 0; i < fibers.size(); ++i)
            EXPECT_LE(dist(fiber_of(s, i).back(), fibers[i].back()), bound) << how << ", fiber " << i;
    };
    for (const std::string& name : available_decoders()) {
        DecodeOptions o;
        o.decoder = parse_decoder(name);
        check(decode_fibers(file, 0, fibers.size(), o), name);
    }
    Streamlines whole;
    decode_file(file, [&](std::uint64_t first, const Streamlines& chunk) {
        for (std::size_t i = 0; i < chunk.size(); ++i) {
            for (std::uint64_t k = chunk.offsets[i]; k < chunk.offsets[i + 1]; ++k)
                whole.xyz.insert(whole.xyz.end(), &chunk.xyz[3 * k], &chunk.xyz[3 * k + 3]);
            whole.offsets.push_back(whole.xyz.size() / 3);
        }
        (void)first;
    });
    check(whole, "decode_file");
    check(select_streamlines(file, BlockIndex::load(file), Query{}), "select_streamlines");
}

// A subset written as a .fft keeps the fractions of the fibers it keeps
// whole, and ends a fiber cut before its last block on a whole step.
TEST(FiberEnds, SubsetFilesCarryTheFractionsOfTheirFibers) {
    test::TempDir dir;
    std::vector<Fiber> fibers;
    for (int k = 0; k < 8; ++k) {
        std::vector<double> inc(100 + 9 * k, 0.1);
        inc.back() = 0.03 + 0.005 * k;
        fibers.push_back(helix(inc, {float(k), 0, 0}));
    }
    const Encoded e = encode(dir, fibers);
    const FftFile file(dir.file("out.fft"));
    std::vector<SelectedRun> runs;
    for (std::uint64_t f = 7; f-- > 0;) runs.push_back({f, file.first_block(f), file.block_count(f), 0});
    runs.push_back({7, file.first_block(7), 1, 0});  // fiber 7 cut after its first block
    write_fft_subset(file, runs, dir.file("subset.fft"), true);
    const FftFile subset(dir.file("subset.fft"));
    ASSERT_TRUE(subset.end_fractions());
    const Streamlines s = decode_fibers(subset, 0, subset.header().fibers);
    for (std::size_t i = 0; i < 7; ++i) {
        const Fiber got = fiber_of(s, i), want = fiber_of(e.decoded, runs[i].fiber);
        ASSERT_EQ(got.size(), want.size());
        EXPECT_EQ(got.back(), want.back()) << "fiber " << runs[i].fiber;
    }
    const Fiber cut = fiber_of(s, 7), whole = fiber_of(e.decoded, 7);
    ASSERT_EQ(cut.size(), 60u);
    EXPECT_EQ(cut.back(), whole[59]);  // a middle block's last point: no fraction
    EXPECT_EQ((*subset.end_fractions())[7], kWholeLastStep);
}

// What a reader that ignores the chunk (the official decoder) sees: the last
// point one whole step from the one before, on the way to the true end.
TEST(FiberEnds, ReadersIgnoringTheChunkSeeAtMostOneStepMore) {
    test::TempDir dir;
    std::vector<Fiber> fibers;
    for (int k = 0; k < 20; ++k) {
        std::vector<double> inc(70 + 3 * k, 0.1);
        inc.back() = 0.005 * (k + 1);
        fibers.push_back(helix(inc, {float(k), 0, 0}));
    }
    const Encoded e = encode(dir, fibers);
    const FftFile file(dir.file("out.fft"));
    const DecodeContext raw(file.header());  // no fractions: the blocks as they decode
    const auto blocks = file.read_blocks(0, file.header().blocks);
    std::vector<float> xyz(3 * count_block_points(raw, blocks.data(), file.header().blocks));
    decode_blocks(raw, blocks.data(), file.header().blocks, xyz.data());
    const double err = double(e.report.header.max_error_mm) + 1e-6, step = e.report.step_mm * e.report.step_scale;
    std::size_t coded_ends = 0;
    for (std::size_t i = 0; i < fibers.size(); ++i) {
        const std::uint64_t last = e.decoded.offsets[i + 1] - 1;
        const std::uint64_t n = last + 1 - e.decoded.offsets[i];
        const Vec3f stored{xyz[3 * last], xyz[3 * last + 1], xyz[3 * last + 2]};
        if ((n - 1) % file.header().points_per_block + 1 <= 2) {  // the end is an anchor: exact for everyone
            EXPECT_LE(dist(stored, fibers[i].back()), err) << "fiber " << i;
            continue;
        }
        ++coded_ends;
        const Vec3f seen{xyz[3 * last], xyz[3 * last + 1], xyz[3 * last + 2]};
        const Vec3f prev{xyz[3 * last - 3], xyz[3 * last - 2], xyz[3 * last - 1]};
        EXPECT_LE(dist(seen, fibers[i].back()), step - dist(prev, fibers[i].back()) + 2 * err) << "fiber " << i;
        EXPECT_GT(dist(seen, fibers[i].back()), 0.5 * (0.1 - 0.005 * (i + 1))) << "fiber " << i;
    }
    EXPECT_GT(coded_ends, 10u);
}

TEST(FiberEnds, FixedStepFilesCarryNoChunk) {
    test::TempDir dir;
    std::vector<Fiber> fibers{helix(std::vector<double>(200, 0.1)), helix(std::vector<double>(61, 0.1), {1, 1, 1})};
    const Encoded e = encode(dir, fibers);
    EXPECT_FALSE(e.report.resampled);
    EXPECT_FALSE(FftFile(dir.file("out.fft")).end_fractions());
    expect_ends_and_lengths(fibers, e);
}

TEST(FiberEnds, ChunkOfTheWrongSizeIsRejected) {
    const TrailerChunk c = make_fiber_ends_chunk(std::vector<std::uint16_t>{1, 2, 3});
    EXPECT_EQ(parse_fiber_ends_chunk(c, 3, "f").size(), 3u);
    EXPECT_THROW(parse_fiber_ends_chunk(c, 4, "f"), Error);
    EXPECT_EQ(quantize_end_fraction(2.0), kWholeLastStep);
    EXPECT_EQ(quantize_end_fraction(-1.0), 0);
    const Vec3f p = place_end_point({0, 0, 0}, {2, 0, 0}, quantize_end_fraction(0.25));
    EXPECT_NEAR(p.x, 0.5, 1e-4);
}

// The end fraction that keeps a fiber's length (fiber_end_encoder.hpp)
// against a brute-force scan of [0, 1]: of the fractions whose end point
// stays within the allowance (the fiber's largest other point error, or
// the closest the segment comes to the end if that is farther), the one
// whose decoded length comes closest to the target.
TEST(FiberEnds, LengthKeepingFractionIsTheClosestAllowedByBruteForce) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    auto d = [](Vec3f a, Vec3f b) {
        const double x = double(a.x) - b.x, y = double(a.y) - b.y, z = double(a.z) - b.z;
        return std::sqrt(x * x + y * y + z * z);
    };
    for (int trial = 0; trial < 300; ++trial) {
        SCOPED_TRACE(trial);
        // Targets 1 mm apart along x, the last a remainder; decoded within 0.05 mm.
        const std::size_t n = 3 + std::size_t(trial % 5);
        std::vector<Vec3f> targets(n), decoded(n);
        for (std::size_t k = 0; k < n; ++k) targets[k] = {float(k), 0, 0};
        targets[n - 1].x = float(n - 2) + float(0.2 + 0.7 * (u(rng) + 1) / 2);
        for (std::size_t k = 0; k + 1 < n; ++k)
            decoded[k] = {targets[k].x + float(0.05 * u(rng)), float(0.05 * u(rng)), float(0.05 * u(rng))};
        decoded[n - 1] = {decoded[n - 2].x + 1.0f, decoded[n - 2].y + float(0.05 * u(rng)), decoded[n - 2].z};
        double before = 0, other = 0;
        for (std::size_t k = 1; k + 1 < n; ++k) before += d(decoded[k - 1], decoded[k]);
        for (std::size_t k = 0; k + 1 < n; ++k) other = std::max(other, d(decoded[k], targets[k]));
        const double target = before + d(decoded[n - 2], targets[n - 1]) + 0.3 * u(rng);
        const Vec3f a = decoded[n - 2], b = decoded[n - 1];
        // The end placed at fraction f, its distance to the true end (in double).
        const Vec3f e = targets[n - 1];
        auto end_miss = [&](double f) {
            const double x = a.x + f * (double(b.x) - a.x) - e.x, y = a.y + f * (double(b.y) - a.y) - e.y,
                         z = a.z + f * (double(b.z) - a.z) - e.z;
            return std::sqrt(x * x + y * y + z * z);
        };
        constexpr int kSteps = 200000;
        double closest = 1e9;
        for (int i = 0; i <= kSteps; ++i) closest = std::min(closest, end_miss(double(i) / kSteps));
        const double allowed = std::max(other, closest);
        double best_f = -1, best = 1e9;
        for (int i = 0; i <= kSteps; ++i) {
            const double f = double(i) / kSteps;
            if (end_miss(f) > allowed) continue;
            const double miss = std::fabs(before + f * d(a, b) - target);
            if (miss < best) best = miss, best_f = f;
        }
        ASSERT_GE(best_f, 0);
        const double f = detail::length_keeping_fraction(decoded, targets, target);
        // Within the allowance (to float rounding) and at least as close to
        // the length as the scan (whose grid may miss the interval's edge).
        EXPECT_LE(end_miss(f), allowed + 1e-6);
        EXPECT_LE(std::fabs(before + f * d(a, b) - target), best + 1e-5);
    }
}

// The largest distance of decoded[from, to) from their targets, both decoders.
double largest_error(const Fiber& targets, const Fiber& decoded, const Fiber& exact, std::size_t from, std::size_t to) {
    double e = 0;
    for (std::size_t k = from; k < to; ++k) e = std::max({e, dist(decoded[k], targets[k]), dist(exact[k], targets[k])});
    return e;
}

// 0.1 mm walks turning up to 12 degrees a step, near the middle of the box.
Fiber walk(std::mt19937& rng, std::size_t points) {
    std::uniform_real_distribution<double> u(-1, 1);
    double p[3] = {5 * u(rng), 5 * u(rng), 5 * u(rng)}, d[3] = {u(rng), u(rng), u(rng)};
    Fiber f;
    for (std::size_t k = 0; k < points; ++k) {
        f.push_back({float(p[0]), float(p[1]), float(p[2])});
        for (double& c : d) c += 0.2 * u(rng);
        const double m = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int a = 0; a < 3; ++a) d[a] /= m, p[a] += 0.1 * d[a];
    }
    return f;
}

FftHeader walk_header() {
    FftHeader h;
    h.scaling = 200;  // an anchor quantum of 3 um, about the point error (as on the 0.1 mm bundles)
    h.offset = {0, 0, 0};
    h.ratio = 0.1f;
    h.step = float(0.1 / h.scaling);
    return h;
}

// A fiber whose last block holds one or two points ends on anchors, which no
// ENDS fraction moves (fiber_end_encoder.hpp): asked for a length 1.5 times
// its point error away from what its codes give, the encoder rounds those
// anchors to neighbouring quanta that keep the length within that error.
// The nearest rounding (before) leaves the whole 1.5 times. Lengths and
// errors by brute force over the decoded points, and the anchors checked
// against the words written in the block.
TEST(FiberEnds, EndAnchorsAreRoundedToKeepTheLength) {
    const FftHeader h = walk_header();
    const FiberEncoder encoder(h, {1, 1, 0, 1, 0});
    std::mt19937 rng(7);
    for (int trial = 0; trial < 40; ++trial) {
        SCOPED_TRACE(trial);
        const std::uint32_t last_points = 1 + std::uint32_t(trial % 2);
        const Fiber f = walk(rng, 2 * h.points_per_block + last_points);
        const std::size_t n = f.size(), i0 = n - last_points;
        std::vector<std::uint8_t> blocks;
        Fiber decoded, exact, scratch;
        detail::encode_keeping_end(encoder, f, false, 0.1, 0, blocks, decoded, &exact, scratch, 0);  // length unknown
        ASSERT_EQ(exact.size(), n);
        const double coded = length_of(decoded), other = largest_error(f, decoded, exact, 0, i0);
        const double target = coded + (trial % 4 < 2 ? 1.25 : -1.25) * other;
        blocks.clear(), decoded.clear(), exact.clear();
        const detail::FiberEnd end = detail::encode_keeping_end(encoder, f, false, 0.1, 0, blocks, decoded, &exact, scratch, target);
        EXPECT_EQ(end.fraction, kWholeLastStep);
        EXPECT_EQ(largest_error(f, decoded, exact, 0, i0), other) << "only the end anchors move";
        EXPECT_LE(std::fabs(length_of(decoded) - target), other) << "the length within the fiber's point error";
        EXPECT_LE(largest_error(f, decoded, exact, i0, n), other * (1 + 1e-9)) << "the anchors within it";
        const BlockView last{&blocks[blocks.size() - h.block_bytes()]};
        const std::array<float, 6> a = last.anchors_normalized();
        for (std::uint32_t k = 0; k < last_points; ++k) {
            const Vec3f written = h.to_world(a[3 * k], a[3 * k + 1], a[3 * k + 2]);
            EXPECT_EQ(dist(written, decoded[i0 + k]), 0.0) << "what the decoders read";
        }
    }
}

// Given a budget (the file's recorded max error is at least that), a fiber's
// end is placed again within it: the end fraction and the end anchors alike
// take a length 2.5 times the fiber's own point error away to within the
// budget of twice that error, which the fiber's own error does not allow.
TEST(FiberEnds, EndsArePlacedAgainWithinABudget) {
    const FftHeader h = walk_header();
    const FiberEncoder encoder(h, {1, 1, 0, 1, 0});
    std::mt19937 rng(8);
    for (int trial = 0; trial < 30; ++trial) {
        SCOPED_TRACE(trial);
        const std::uint32_t last_points = trial % 3 == 0 ? 1 : trial % 3 == 1 ? 2 : 30;
        const Fiber f = walk(rng, 2 * h.points_per_block + last_points);
        const std::size_t n = f.size(), moved = last_points >= 3 ? 1 : last_points;
        std::vector<std::uint8_t> blocks;
        Fiber decoded, exact, scratch;
        detail::encode_keeping_end(encoder, f, false, 0.1, 0, blocks, decoded, &exact, scratch, 0);
        const double coded = length_of(decoded), other = largest_error(f, decoded, exact, 0, n - moved);
        // (A fraction only shortens the last step: the codes' zig-zag makes fibers too long.)
        const double target = coded + (trial % 2 && last_points < 3 ? 2.5 : -2.5) * other, budget = 2 * other;
        blocks.clear(), decoded.clear(), exact.clear();
        const detail::FiberEnd end = detail::encode_keeping_end(encoder, f, false, 0.1, 0, blocks, decoded, &exact, scratch, target);
        EXPECT_GT(std::fabs(length_of(decoded) - target), 1.2 * other) << "the fiber's own error is not enough";
        const std::uint16_t q = detail::place_end_within(h, end, &blocks[blocks.size() - h.block_bytes()], f, decoded,
                                                         exact, target, budget);
        EXPECT_EQ(q == kWholeLastStep, last_points < 3 && end.fraction == kWholeLastStep);
        EXPECT_LE(std::fabs(length_of(decoded) - target), budget) << "the length within the budget";
        EXPECT_LE(largest_error(f, decoded, exact, n - moved, n), budget) << "the moved points within it";
        EXPECT_EQ(largest_error(f, decoded, exact, 0, n - moved), other) << "the others unmoved";
    }
}

}  // namespace
}  // namespace fiblet
