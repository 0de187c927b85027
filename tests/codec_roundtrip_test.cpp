// Round trip .tck -> .fft -> points on the shared tractograms: structure
// (fibers, points per fiber, IDs, flags) is preserved, the header's recorded
// error equals a brute-force measurement, and every point is within the
// closed-loop bound of codes at most one level from the aimed one.
#include <gtest/gtest.h>

#include <cmath>

#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/direction_code.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "error_bound.hpp"
#include "exact_error.hpp"
#include "test_util.hpp"

using namespace fiblet;

namespace {

double dist(const float* p, Vec3f q) {
    const double dx = double(p[0]) - q.x, dy = double(p[1]) - q.y, dz = double(p[2]) - q.z;
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}
double dist(Vec3f p, Vec3f q) {
    const float a[3] = {p.x, p.y, p.z};
    return dist(a, q);
}

// Largest angle from a direction inside the cap to its nearest code,
// measured by brute force on a dense sample (plus a margin for sampling).
double covering_angle(const DirectionTable& t) {
    const double ratio = t.ratio();
    double worst = 0;
    for (int i = 0; i <= 200; ++i) {
        const double cx = 1.0 - std::min(ratio, 2.0) * i / 200.0;
        const double s = std::sqrt(std::max(0.0, 1 - cx * cx));
        for (int j = 0; j < 360; ++j) {
            const double phi = 2 * M_PI * j / 360.0;
            const double d[3] = {cx, s * std::cos(phi), s * std::sin(phi)};
            double best = -2;
            for (int k = 0; k < 256; ++k) {
                const Vec3f c = t.direction(std::uint8_t(k));
                best = std::max(best, c.x * d[0] + c.y * d[1] + c.z * d[2]);
            }
            worst = std::max(worst, std::acos(std::min(best, 1.0)));
        }
    }
    return worst * 1.05;
}

struct Case {
    const char* file;
};

class CodecRoundTrip : public ::testing::TestWithParam<Case> {};

TEST_P(CodecRoundTrip, PreservesStructureAndStaysWithinTheErrorBound) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    const std::string input = test::shared_data(GetParam().file);
    test::TempDir dir;
    const std::string out = dir.file("out.fft");
    CompressOptions o;
    o.direction_bits = 8;  // the 8-bit layout's blocks (the default gives small-sdstream 16 bits)
    const CompressReport report = compress_file(input, out, o);
    ASSERT_FALSE(report.resampled) << "fixed-step input must not be resampled";

    const FftFile file(out);
    const FftHeader& h = file.header();
    const auto ref = test::read_tck_fibers(input);
    ASSERT_EQ(h.fibers, ref.size());
    const Streamlines s = decode_fibers(file, 0, h.fibers);
    ASSERT_EQ(s.size(), ref.size());

    // Structure: block flags, fiber IDs and block indices.
    const auto blocks = file.read_blocks(0, h.blocks);
    for (std::uint64_t f = 0; f < h.fibers; ++f) {
        ASSERT_EQ(s.offsets[f + 1] - s.offsets[f], ref[f].size()) << "fiber " << f;
        const std::uint32_t nb = file.block_count(f);
        ASSERT_EQ(nb, (ref[f].size() + 59) / 60);
        for (std::uint32_t b = 0; b < nb; ++b) {
            const BlockView v{&blocks[(file.first_block(f) + b) * h.block_bytes()]};
            ASSERT_EQ(v.fiber_id(), f);
            ASSERT_EQ(v.index_in_fiber(), b % 256);
            ASSERT_EQ(v.is_first(), b == 0);
            ASSERT_EQ(v.is_last(), b + 1 == nb);
            ASSERT_EQ(v.point_count(), std::min<std::size_t>(60, ref[f].size() - 60 * b));
        }
    }

    // Brute-force error, and the closed-loop bound per point: with anchor
    // error ea (one unorm16 step on each axis), step length delta, true
    // spacing s_k and covering angle theta of the code set over the cap,
    //   e_{k+1} <= |D - delta| + sqrt(delta * D) * theta,  D = |t_{k+1} - p_k| <= s_k + e_k
    // so b_{k+1} = b_k + |s_k - delta| + sqrt(delta * (s_k + b_k)) * theta bounds e_{k+1}.
    const DirectionTable table(h.ratio);
    // The default search (lookahead, retry beam) may take any code of the
    // aimed one's 3x3 (formats/error-bound.md, "Setting"): its reach adds to
    // the covering angle.
    const double theta = covering_angle(table) + test::neighbourhood_reach(table, 1);
    const double delta = double(h.step) * h.scaling;
    // A full quantum: the encoder may round anchors the other way where the
    // first frame is ill-conditioned (encode/anchor_conditioning.hpp).
    const double ea = std::sqrt(3.0) * h.scaling / 65535.0 + 1e-6;
    double max_e = 0, sum_e = 0;
    std::uint64_t n = 0, over = 0;
    for (std::uint64_t f = 0; f < h.fibers; ++f) {
        const float* p = &s.xyz[3 * s.offsets[f]];
        double bound = ea;
        for (std::size_t i = 0; i < ref[f].size(); ++i) {
            const double e = dist(p + 3 * i, ref[f][i]);
            max_e = std::max(max_e, e), sum_e += e, ++n;
            if (i % 60 <= 1) {
                bound = ea;  // anchors
            } else {
                const double sk = dist(ref[f][i - 1], ref[f][i]);
                bound += std::fabs(sk - delta) + std::sqrt(delta * (sk + bound)) * theta;
            }
            over += e > bound * (1 + 1e-4) + 1e-7;
        }
    }
    EXPECT_EQ(over, 0u) << "points above the closed-loop bound";
    // The header records the worse of fiblet's float decode and the exact
    // (float64) decode at each point (exact_decode_test.cpp).
    const auto exact = test::measure_exact(out, input);
    const double both_max = std::max(max_e, exact.exact.max_mm), mean_e = sum_e / double(n);
    EXPECT_NEAR(h.max_error_mm, both_max, 1e-3 * both_max + 1e-7);
    EXPECT_GE(h.mean_error_mm, std::max(mean_e, exact.exact.mean_mm()) * (1 - 1e-3));
    EXPECT_LE(h.mean_error_mm, std::max(mean_e, exact.exact.mean_mm()) * 1.01);
    EXPECT_NEAR(report.error.max_mm(), both_max, 1e-3 * both_max + 1e-7);
    // A sanity floor on usefulness: errors far below the step.
    EXPECT_LT(max_e, 0.25 * delta);
}

INSTANTIATE_TEST_SUITE_P(SharedTractograms, CodecRoundTrip,
                         ::testing::Values(Case{"small-ifod1.tck"}, Case{"small-sdstream.tck"},
                                           Case{"small-ifod1-step0.05.tck"}, Case{"dwi-small64d-ifod1.tck"}),
                         [](const auto& info) {
                             std::string n = info.param.file;
                             for (char& c : n)
                                 if (!isalnum(static_cast<unsigned char>(c))) c = '_';
                             return n;
                         });

}  // namespace
