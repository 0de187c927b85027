// The direction bits compress chooses when none are asked for
// (CompressOptions::direction_bits unset, `--bits auto`): 16 where the 8-bit
// codes would change the sampled fibers' lengths by more than their point
// error (smooth fixed-step fibers: the 8-bit grid has no straight-ahead code,
// so they zig-zag and grow), else 8. Lengths are measured by brute force on
// the decoded file, with fiblet's decoder and the float64 reference decoder.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "exact_decoder.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

namespace fiblet {
namespace {

constexpr double kStep = 0.1;  // mm, as SD_STREAM and the 0.1 mm bundles

// Long, smooth fibers at a fixed 0.1 mm step, like SD_STREAM's: bending
// gently (1/150 mm^-1), with a 15 degree corner every 20 mm, which sizes
// the cap as the sharpest turns of real data do; 60 to 83 mm long. With
// `drop_every` > 0 every drop_every-th point is left out (variable spacing:
// compress resamples them, as the 0.1 mm bundles).
void write_smooth_fibers(const std::string& path, int drop_every = 0) {
    TckWriter w(path, {{"step_size", "0.1"}}, true);
    for (int i = 0; i < 24; ++i) {
        const double plane = 0.26 * i;
        double heading = 0, x = 0.3 * i, y = 0, z = -40;
        std::vector<Vec3f> f;
        for (int k = 0; k < 600 + 10 * i; ++k) {
            if (drop_every == 0 || k % drop_every != drop_every - 1) f.push_back({float(x), float(y), float(z)});
            heading += kStep / 150 + (k % 200 == 199 ? 0.26 : 0.0);
            const double u = std::sin(heading), v = std::cos(heading);
            x += kStep * u * std::cos(plane), y += kStep * u * std::sin(plane), z += kStep * v;
        }
        w.write(f);
    }
    w.finish();
}

// A random walk of `points` at a fixed 0.1 mm step from (x0, 0, 0), its
// direction jittered by up to `turn` / 2 per axis a step (deterministic:
// mt19937's raw output).
std::vector<Vec3f> random_walk(std::mt19937& rng, double x0, int points, double turn) {
    auto uniform = [&] { return double(rng()) / 4294967296.0 - 0.5; };  // [-0.5, 0.5)
    double dx = 1, dy = 0, dz = 0, x = x0, y = 0, z = 0;
    std::vector<Vec3f> f;
    for (int k = 0; k < points; ++k) {
        f.push_back({float(x), float(y), float(z)});
        dx += turn * uniform(), dy += turn * uniform(), dz += turn * uniform();
        const double n = std::sqrt(dx * dx + dy * dy + dz * dz);
        dx /= n, dy /= n, dz /= n;
        x += kStep * dx, y += kStep * dy, z += kStep * dz;
    }
    return f;
}

// iFOD1-like fibers: random walks turning up to ~10 degrees a step.
void write_jittery_fibers(const std::string& path) {
    TckWriter w(path, {{"step_size", "0.1"}}, true);
    std::mt19937 rng(11);
    for (int i = 0; i < 40; ++i) w.write(random_walk(rng, i, 500, 0.35));
    w.finish();
}

// A file the sample misreads: 299 iFOD1-like walks (turning up to ~14
// degrees a step: their codes keep their lengths) and, at index 1, one
// smooth 100 mm fiber, whose 8-bit zig-zag grows it beyond the point error.
// 150 k points: the bits sample keeps every other fiber, not fiber 1.
void write_walks_and_one_smooth_fiber(const std::string& path) {
    TckWriter w(path, {{"step_size", "0.1"}}, true);
    std::mt19937 rng(5);
    for (int i = 0; i < 300; ++i) {
        if (i != 1) {
            w.write(random_walk(rng, 0.1 * i, 500, 0.5));
            continue;
        }
        std::vector<Vec3f> f;
        double heading = 0, x = 0.5, z = -40;
        for (int k = 0; k < 1000; ++k) {
            f.push_back({float(x), 0, float(z)});
            heading += kStep / 150;
            x += kStep * std::sin(heading), z += kStep * std::cos(heading);
        }
        w.write(f);
    }
    w.finish();
}

double length_of(const float* p, std::uint64_t n) {
    double l = 0;
    for (std::uint64_t k = 1; k < n; ++k) {
        const double dx = double(p[3 * k]) - p[3 * k - 3], dy = double(p[3 * k + 1]) - p[3 * k - 2],
                     dz = double(p[3 * k + 2]) - p[3 * k - 1];
        l += std::sqrt(dx * dx + dy * dy + dz * dz);
    }
    return l;
}

double length_of(const std::vector<test::exact::V3>& e) {
    double l = 0;
    for (std::size_t k = 1; k < e.size(); ++k) l += std::sqrt(test::exact::dot(e[k] - e[k - 1], e[k] - e[k - 1]));
    return l;
}

struct LengthChanges {
    double fiblet = 0, exact = 0;  // largest |decoded - input length|, mm
};

// Every fiber's length change in `fft` against `tck`, by brute force (the
// float64 decode, which applies the ENDS fraction as formats/fft-ends.md says).
LengthChanges length_changes(const std::string& tck, const std::string& fft) {
    const FftFile file(fft);
    const Streamlines s = decode_fibers(file, 0, file.header().fibers);
    const std::string bytes = test::read_file(fft);
    const test::exact::Decoded exact = test::exact::decode(bytes);
    TckReader in(tck);
    std::vector<Vec3f> f;
    LengthChanges out;
    for (std::size_t i = 0; in.next(f); ++i) {
        const double li = length_of(&f[0].x, f.size());
        out.fiblet = std::max(out.fiblet, std::fabs(length_of(&s.xyz[3 * s.offsets[i]], s.offsets[i + 1] - s.offsets[i]) - li));
        out.exact = std::max(out.exact, std::fabs(length_of(exact.fibers[i]) - li));
    }
    return out;
}

// Every fiber within the header's max error (fiblet's decoder), 1.05x it
// (float64).
void expect_lengths_within_the_recorded_error(const LengthChanges& c, const FftHeader& h) {
    const double recorded = double(h.max_error_mm) * (1 + 1e-6) + 1e-7;
    EXPECT_LE(c.fiblet, recorded);
    EXPECT_LE(c.exact, 1.05 * recorded);
}

CompressReport compress(const std::string& tck, const std::string& fft, std::optional<unsigned> bits,
                        unsigned threads = 0) {
    CompressOptions o;
    o.overwrite = true;
    o.direction_bits = bits;
    o.threads = threads;
    return compress_file(tck, fft, o);
}

}  // namespace

TEST(DirectionBits, SmoothFibersGetSixteenBitsAndKeepTheirLengths) {
    test::TempDir dir;
    write_smooth_fibers(dir.file("smooth.tck"));
    // At 8 bits (forced) the zig-zag grows the fibers beyond their point error.
    const CompressReport r8 = compress(dir.file("smooth.tck"), dir.file("8.fft"), 8u);
    EXPECT_EQ(r8.header.version, kFftVersion);
    EXPECT_FALSE(r8.bits.automatic);
    EXPECT_EQ(r8.bits.reason, "8 bits");
    const LengthChanges c8 = length_changes(dir.file("smooth.tck"), dir.file("8.fft"));
    EXPECT_GT(c8.fiblet, 1.5 * double(r8.header.max_error_mm));  // measured: 4.8 um for 2.4 um

    const CompressReport r = compress(dir.file("smooth.tck"), dir.file("auto.fft"), std::nullopt);
    EXPECT_TRUE(r.bits.automatic);
    ASSERT_EQ(r.header.direction_bits(), 16u);
    EXPECT_EQ(r.header.version, kFft16PackedVersion);
    EXPECT_NE(r.bits.reason.find("16 bits"), std::string::npos) << r.bits.reason;
    // The sample is the whole file here: what it measured at 8 bits is what
    // the 8-bit file shows, by brute force and in its header.
    EXPECT_EQ(r.bits.sample_fibers, 24u);
    EXPECT_NEAR(r.bits.length_change_max_mm, std::max(c8.fiblet, c8.exact), 1e-5);
    EXPECT_NEAR(r.bits.point_error_max_mm, double(r8.header.max_error_mm), 1e-6);
    expect_lengths_within_the_recorded_error(length_changes(dir.file("smooth.tck"), dir.file("auto.fft")), r.header);
    // The same file as asking for 16 bits (fixed-step input: tuned alike).
    compress(dir.file("smooth.tck"), dir.file("16.fft"), 16u);
    EXPECT_TRUE(test::read_file(dir.file("auto.fft")) == test::read_file(dir.file("16.fft")));
}

// Resampled input is measured as pass 2 encodes it: resampled with its
// fitted tension, its end kept (ENDS). The sample is the whole file here,
// so what it measured is what the 8-bit file shows. These smooth fibers
// keep their lengths at 8 bits once resampled (the length feedback across
// blocks: 0.8 um for 1.3 um measured), so they stay 8-bit.
TEST(DirectionBits, ResampledInputIsMeasuredAsPassTwoEncodesIt) {
    test::TempDir dir;
    write_smooth_fibers(dir.file("gaps.tck"), 4);  // spacing 0.1, 0.1, 0.2 mm
    const CompressReport r = compress(dir.file("gaps.tck"), dir.file("auto.fft"), std::nullopt);
    ASSERT_TRUE(r.resampled);
    EXPECT_EQ(r.header.direction_bits(), 8u) << r.bits.reason;
    EXPECT_EQ(r.bits.sample_fibers, 24u);
    const LengthChanges c = length_changes(dir.file("gaps.tck"), dir.file("auto.fft"));
    EXPECT_NEAR(r.bits.length_change_max_mm, std::max(c.fiblet, c.exact), 1e-5);
    EXPECT_NEAR(r.bits.point_error_max_mm, double(r.header.max_error_mm), 1e-6);
    expect_lengths_within_the_recorded_error(c, r.header);
    compress(dir.file("gaps.tck"), dir.file("8.fft"), 8u);
    EXPECT_TRUE(test::read_file(dir.file("auto.fft")) == test::read_file(dir.file("8.fft")));
}

TEST(DirectionBits, JitteryFibersKeepEightBits) {
    test::TempDir dir;
    write_jittery_fibers(dir.file("walk.tck"));
    const CompressReport r = compress(dir.file("walk.tck"), dir.file("auto.fft"), std::nullopt);
    EXPECT_TRUE(r.bits.automatic);
    EXPECT_EQ(r.header.version, kFftVersion);
    EXPECT_EQ(r.bits.sample_fibers, 40u);
    EXPECT_LE(r.bits.length_change_max_mm, r.bits.point_error_max_mm);
    // And the whole file keeps them, as the sample said.
    expect_lengths_within_the_recorded_error(length_changes(dir.file("walk.tck"), dir.file("auto.fft")), r.header);
    // The choice is the same as asking for 8 bits: the same bytes.
    compress(dir.file("walk.tck"), dir.file("8.fft"), 8u);
    EXPECT_TRUE(test::read_file(dir.file("auto.fft")) == test::read_file(dir.file("8.fft")));
}

TEST(DirectionBits, TheSameBytesWithOneOrTwoThreads) {
    test::TempDir dir;
    write_smooth_fibers(dir.file("smooth.tck"));
    const CompressReport one = compress(dir.file("smooth.tck"), dir.file("1.fft"), std::nullopt, 1);
    const CompressReport two = compress(dir.file("smooth.tck"), dir.file("2.fft"), std::nullopt, 2);
    EXPECT_EQ(one.header.direction_bits(), 16u);
    EXPECT_EQ(one.bits.reason, two.bits.reason);
    EXPECT_TRUE(test::read_file(dir.file("1.fft")) == test::read_file(dir.file("2.fft")));
}

TEST(DirectionBits, CliBitsOptionAndStandardInput) {
    test::TempDir dir;
    write_smooth_fibers(dir.file("smooth.tck"));
    const std::string cli = FIBLET_CLI;
    // --bits auto: chosen, said in the report.
    const auto json = test::run_cli("compress -q -f --json --bits auto " + dir.file("smooth.tck") + " -o " + dir.file("a.fft"));
    ASSERT_EQ(json.status, 0) << json.output;
    EXPECT_NE(json.output.find("\"direction_bits\": 16"), std::string::npos) << json.output;
    EXPECT_NE(json.output.find("\"bits_automatic\": true"), std::string::npos) << json.output;
    EXPECT_NE(json.output.find("\"bits_reason\": \"16 bits: 8-bit codes would change lengths"), std::string::npos)
        << json.output;
    const auto text = test::run_cli("compress -f --bits auto " + dir.file("smooth.tck") + " -o " + dir.file("b.fft"));
    ASSERT_EQ(text.status, 0) << text.output;
    EXPECT_NE(text.output.find("16 bits: 8-bit codes would change lengths by up to"), std::string::npos) << text.output;
    EXPECT_TRUE(test::read_file(dir.file("a.fft")) == test::read_file(dir.file("b.fft")));
    // Standard input: the same choice from the one read the CLI spools, the same bytes.
    ASSERT_EQ(test::run_command("cat " + dir.file("smooth.tck") + " | " + cli + " compress -q --bits auto - -o " + dir.file("c.fft")).status, 0);
    EXPECT_TRUE(test::read_file(dir.file("a.fft")) == test::read_file(dir.file("c.fft")));
    // The default is 8 bits, the official layout, whatever the data.
    const auto eight = test::run_cli("compress -q -f --json " + dir.file("smooth.tck") + " -o " + dir.file("d.fft"));
    ASSERT_EQ(eight.status, 0) << eight.output;
    EXPECT_NE(eight.output.find("\"direction_bits\": 8"), std::string::npos) << eight.output;
    EXPECT_NE(eight.output.find("\"bits_automatic\": false"), std::string::npos) << eight.output;
    EXPECT_EQ(FftFile(dir.file("d.fft")).header().version, kFftVersion);
    // Anything else is refused.
    const auto bad = test::run_cli("compress -q -f --bits 12 " + dir.file("smooth.tck") + " -o " + dir.file("e.fft"));
    EXPECT_NE(bad.status, 0);
}

// Where the sample keeps its lengths at 8 bits but the whole file does not
// (the sample left out the fiber that grows), compress says so and what
// keeps them; --bits 16 does.
TEST(DirectionBits, CliNotesLengthsTheSampleMissed) {
    test::TempDir dir;
    write_walks_and_one_smooth_fiber(dir.file("mix.tck"));
    const auto r = test::run_cli("compress -f --bits auto " + dir.file("mix.tck") + " -o " + dir.file("a.fft"));
    ASSERT_EQ(r.status, 0) << r.output;
    const FftFile a(dir.file("a.fft"));
    ASSERT_EQ(a.header().version, kFftVersion) << r.output;
    const LengthChanges eight = length_changes(dir.file("mix.tck"), dir.file("a.fft"));
    EXPECT_GT(eight.fiblet, double(a.header().max_error_mm) * 1.5) << "the test file no longer shows the miss";
    EXPECT_NE(r.output.find("fiblet: note: " + dir.file("a.fft") + ": a fiber's length changed by"), std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("(fiber 1;"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("--bits 16 keeps lengths"), std::string::npos) << r.output;
    // At the default 8 bits the same note points to --bits auto.
    const auto by_default = test::run_cli("compress -f " + dir.file("mix.tck") + " -o " + dir.file("e.fft"));
    EXPECT_NE(by_default.output.find("(fiber 1): --bits auto (16 bits where 8 would not) keeps lengths"), std::string::npos)
        << by_default.output;
    // Quiet means quiet; a file that keeps its lengths gets no note.
    EXPECT_EQ(test::run_cli("compress -q -f " + dir.file("mix.tck") + " -o " + dir.file("b.fft")).output, "");
    write_jittery_fibers(dir.file("walk.tck"));
    const auto kept = test::run_cli("compress -f " + dir.file("walk.tck") + " -o " + dir.file("c.fft"));
    EXPECT_EQ(kept.output.find("note:"), std::string::npos) << kept.output;
    // What the note says holds.
    ASSERT_EQ(test::run_cli("compress -q -f --bits 16 " + dir.file("mix.tck") + " -o " + dir.file("d.fft")).status, 0);
    expect_lengths_within_the_recorded_error(length_changes(dir.file("mix.tck"), dir.file("d.fft")),
                                             FftFile(dir.file("d.fft")).header());
}

}  // namespace fiblet
