// Round trip .tck -> .fft -> points on the shared tractograms: structure
// (fibers, points per fiber, IDs, flags) is preserved, the header's recorded
// error equals a brute-force measurement, every point is within the
// closed-loop bound, and every step is the best one the 256 codes allow.
#include <gtest/gtest.h>

#include <cmath>

#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/direction_code.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

using namespace fiblet;

namespace {

std::vector<std::vector<Vec3f>> read_all(const std::string& path) {
    TckReader r(path);
    std::vector<std::vector<Vec3f>> all;
    std::vector<Vec3f> f;
    while (r.next(f)) all.push_back(f);
    return all;
}

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
    const CompressReport report = compress_tck(input, out, {});
    ASSERT_FALSE(report.resampled) << "fixed-step input must not be resampled";

    const FftFile file(out);
    const FftHeader& h = file.header();
    const auto ref = read_all(input);
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
    // error ea (half a unorm16 step on each axis), step length delta, true
    // spacing s_k and covering angle theta of the code set over the cap,
    //   e_{k+1} <= |D - delta| + sqrt(delta * D) * theta,  D = |t_{k+1} - p_k| <= s_k + e_k
    // so b_{k+1} = b_k + |s_k - delta| + sqrt(delta * (s_k + b_k)) * theta bounds e_{k+1}.
    const DirectionTable table(h.ratio);
    const double theta = covering_angle(table);
    const double delta = double(h.step) * h.scaling;
    const double ea = std::sqrt(3.0) * 0.5 * h.scaling / 65535.0 + 1e-6;
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
    EXPECT_NEAR(h.max_error_mm, max_e, 1e-3 * max_e + 1e-7);
    EXPECT_NEAR(h.mean_error_mm, sum_e / double(n), 1e-3 * sum_e / double(n) + 1e-7);
    EXPECT_NEAR(report.error.max_mm(), max_e, 1e-3 * max_e + 1e-7);
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

// Greedy closed loop: at every step the encoder picks, among all 256 codes,
// the one whose decoded point lands closest to the input point (given the
// decoded previous point and frame, replayed here in double precision).
TEST(CodecEncoder, PicksTheClosestOfAll256CodesAtEveryStep) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    const std::string input = test::shared_data("small-sdstream.tck");
    compress_tck(input, dir.file("o.fft"), {});
    const FftFile file(dir.file("o.fft"));
    const FftHeader& h = file.header();
    const DirectionTable table(h.ratio);
    const auto ref = read_all(input);
    const Streamlines s = decode_fibers(file, 0, 200);
    const auto blocks = file.read_blocks(0, file.block_end(200));
    std::uint64_t steps = 0, worse = 0;
    for (std::uint64_t f = 0; f < 200; ++f) {
        for (std::uint32_t b = 0; b < file.block_count(f); ++b) {
            const BlockView v{&blocks[(file.first_block(f) + b) * h.block_bytes()]};
            for (std::uint32_t k = 2; k < v.point_count(); ++k) {
                const std::size_t i = 60 * b + k;
                const float* prev = &s.xyz[3 * (s.offsets[f] + i - 1)];
                const float* got = &s.xyz[3 * (s.offsets[f] + i)];
                const double chosen = dist(got, ref[f][i]);
                // Replay the block's frames up to this step (the candidate
                // world direction of code c is F * L_c.c0).
                Frame frame = frame_from_axis([&] {
                    const auto a = v.anchors_normalized();
                    Vec3f d{a[3] - a[0], a[4] - a[1], a[5] - a[2]};
                    const float nn = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
                    return nn > 0 ? Vec3f{d.x / nn, d.y / nn, d.z / nn} : Vec3f{1, 0, 0};
                }());
                for (std::uint32_t j = 2; j < k; ++j) {
                    const Frame& l = table.frame(v.directions()[j - 2]);
                    Frame nf;
                    for (int c = 0; c < 3; ++c)
                        nf.c[c] = {frame.c[0].x * l.c[c].x + frame.c[1].x * l.c[c].y + frame.c[2].x * l.c[c].z,
                                   frame.c[0].y * l.c[c].x + frame.c[1].y * l.c[c].y + frame.c[2].y * l.c[c].z,
                                   frame.c[0].z * l.c[c].x + frame.c[1].z * l.c[c].y + frame.c[2].z * l.c[c].z};
                    frame = nf;
                }
                double best = 1e9;
                const double step_mm = double(h.step) * h.scaling;
                for (int c = 0; c < 256; ++c) {
                    const Vec3f d = table.direction(std::uint8_t(c));
                    const double w[3] = {
                        frame.c[0].x * d.x + frame.c[1].x * d.y + frame.c[2].x * d.z,
                        frame.c[0].y * d.x + frame.c[1].y * d.y + frame.c[2].y * d.z,
                        frame.c[0].z * d.x + frame.c[1].z * d.y + frame.c[2].z * d.z};
                    const float cand[3] = {float(prev[0] + step_mm * w[0]), float(prev[1] + step_mm * w[1]),
                                           float(prev[2] + step_mm * w[2])};
                    best = std::min(best, dist(cand, ref[f][i]));
                }
                ++steps;
                worse += chosen > best + 2e-5;  // float rounding of positions (~1e-5 mm at 100 mm)
            }
        }
    }
    EXPECT_GT(steps, 10000u);
    EXPECT_EQ(worse, 0u) << "steps where a better code existed";
}

}  // namespace
