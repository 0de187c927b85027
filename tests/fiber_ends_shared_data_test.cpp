// On every shared tractogram (../shared/data/*.tck and bundles/*.tck, fixed
// step, iFOD2 and 6 mm bundles alike), compressed with the defaults: decoded
// endpoints within the error the file records; lengths as `stats` reports
// them, recomputed here from the decoded points; no length lost beyond the
// chord approximation of resampling (the decoded length matches that of the
// codec's target polyline, the input or its resampling with the end kept, to
// a small part of a step); and, where MRtrix3 is installed, `tckstats
// -output mean` agreeing between the decoded file and those targets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "exact_decoder.hpp"
#include "fiblet/compare.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/block_index.hpp"
#include "fiblet/fiber_ends.hpp"
#include "fiblet/resample.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

namespace fiblet {
namespace {

std::vector<std::string> shared_tractograms() {
    std::vector<std::string> out;
    for (const char* sub : {"", "bundles"})
        for (const auto& e : std::filesystem::directory_iterator(test::shared_data(sub)))
            if (e.path().extension() == ".tck") out.push_back(e.path().string());
    std::sort(out.begin(), out.end());
    return out;
}

double dist(Vec3f a, const float* b) {
    const double dx = double(a.x) - b[0], dy = double(a.y) - b[1], dz = double(a.z) - b[2];
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}

double length_of(const float* p, std::uint64_t n) {
    double l = 0;
    for (std::uint64_t k = 1; k < n; ++k) l += dist({p[3 * k - 3], p[3 * k - 2], p[3 * k - 1]}, p + 3 * k);
    return l;
}

// The length of a float64 (reference decoder) polyline.
double length_of(const std::vector<test::exact::V3>& e) {
    double l = 0;
    for (std::size_t k = 1; k < e.size(); ++k) l += std::sqrt(test::exact::dot(e[k] - e[k - 1], e[k] - e[k - 1]));
    return l;
}

TEST(FiberEndsSharedData, EndpointsAndLengthsMatchTheInput) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    const auto files = shared_tractograms();
    ASSERT_GE(files.size(), 15u);
    test::TempDir dir;
    for (const std::string& tck : files) {
        SCOPED_TRACE(tck);
        CompressOptions o;
        o.overwrite = true;
        const CompressReport r = compress_file(tck, dir.file("f.fft"), o);
        const FftFile file(dir.file("f.fft"));
        const Comparison c = compare_to_reference(file, tck);
        const double recorded = double(file.header().max_error_mm) * (1 + 1e-6) + 1e-7;
        const Streamlines s = decode_fibers(file, 0, file.header().fibers);
        TckReader in(tck);
        std::vector<Vec3f> f, target;
        double end_max = 0, len_max = 0, target_len_max = 0, len_change_sum = 0, len_abs_sum = 0, input_len_sum = 0;
        std::size_t measured = 0;
        for (std::size_t i = 0; in.next(f); ++i) {
            const std::uint64_t n = s.offsets[i + 1] - s.offsets[i];
            if (f.empty()) continue;
            ASSERT_GT(n, 0u);
            const float* p = &s.xyz[3 * s.offsets[i]];
            end_max = std::max({end_max, dist(f.front(), p), dist(f.back(), p + 3 * (n - 1))});
            double li = 0;
            for (std::size_t k = 1; k < f.size(); ++k) li += dist(f[k - 1], &f[k].x);
            len_max = std::max(len_max, std::fabs(length_of(p, n) - li));
            len_change_sum += length_of(p, n) - li, len_abs_sum += std::fabs(length_of(p, n) - li), ++measured;
            input_len_sum += li;
            if (r.resampled) resample_keeping_end(f, *file.resampling(), target);
            else target = f;
            const double lt = length_of(&target[0].x, target.size());
            target_len_max = std::max(target_len_max, std::fabs(length_of(p, n) - lt) - 1e-3 * lt);
        }
        EXPECT_LE(end_max, recorded) << "an endpoint moved more than the recorded error";
        EXPECT_NEAR(c.geometry.endpoint_mm().max, end_max, 1e-6) << "stats reports another endpoint error";
        EXPECT_NEAR(c.geometry.length_change_mm().max, len_max, 1e-5) << "stats reports another length change";
        // (0.2 step: the 4-9 mm steps of the raw bundles zig-zag by up to 0.12 step.)
        EXPECT_LT(target_len_max, 0.2 * r.step_mm) << "a fiber lost length beyond the chords of its resampling";
        // Lengths against the input polylines themselves, on average within
        // 0.1 % (the decoder's tuned step scale: +0.05 % on fixed-step files)
        // and 0.2 step: chords on the cubic keep them (chords on the polyline
        // lost 0.34 mm = 0.67 step on iFOD2, 0.37 %).
        const double mean_input = input_len_sum / double(measured);
        EXPECT_LT(len_abs_sum / double(measured), 1e-3 * mean_input + 0.2 * r.step_mm) << "mean |length change|";
        EXPECT_LT(std::fabs(len_change_sum) / double(measured), 1e-3 * mean_input + 0.15 * r.step_mm)
            << "mean length change";
        if (!r.resampled) {
            EXPECT_LT(len_max, 1e-3 * 250.0) << "a fixed-step fiber changed length by > 0.1 %";
        }
        // Resampled fibers: the tension fit makes each as long as its input
        // (what stays is the codes' lag at block ends, ~0.05 step a fiber,
        // and on 0.1 mm steps the decoder's step scale, 0.03 %; with
        // Bessel's cubic alone iFOD2 was off by 0.15 step).
        if (r.resampled) {
            EXPECT_LT(len_abs_sum / double(measured), 0.1 * r.step_mm + 5e-4 * mean_input) << "mean |length change|";
        }
        EXPECT_LE(c.error.max_mm(), recorded);
    }
}

// Mean length of the codec's target polylines: the input, or its resampling
// with the end kept (what a fixed step can represent).
double mean_target_length(const std::string& tck, const std::string& fft) {
    const FftFile file(fft);
    const std::optional<Resampling> resampling = file.resampling();
    TckReader in(tck);
    std::vector<Vec3f> f, target;
    double sum = 0;
    std::size_t n = 0;
    while (in.next(f)) {
        if (resampling) resample_keeping_end(f, *resampling, target);
        else target = f;
        if (!target.empty()) sum += length_of(&target[0].x, target.size());
        ++n;
    }
    return sum / double(n);
}

// Mean streamline length as tckstats prints it.
double tckstats_mean(const std::string& tck) {
    const auto r = test::run_command("tckstats -quiet -output mean " + tck + " 2>/dev/null");
    EXPECT_EQ(r.status, 0) << tck;
    return std::stod(r.output);
}

TEST(FiberEndsSharedData, TckstatsMeanLengthAgrees) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    if (test::run_command("command -v tckstats >/dev/null").status != 0) GTEST_SKIP() << "tckstats (MRtrix3) not installed";
    test::TempDir dir;
    for (const std::string& tck : shared_tractograms()) {
        SCOPED_TRACE(tck);
        ASSERT_EQ(test::run_cli("compress -q --force " + tck + " -o " + dir.file("f.fft")).status, 0);
        ASSERT_EQ(test::run_cli("decompress -q --force " + dir.file("f.fft") + " -o " + dir.file("d.tck")).status, 0);
        const double before = tckstats_mean(tck), after = tckstats_mean(dir.file("d.tck"));
        const double target = mean_target_length(tck, dir.file("f.fft"));
        // Within 0.1 % of the targets (the decoder's tuned step scale
        // lengthens fibers by ~0.05 %) plus 0.05 step (the zig-zag of coarse
        // codes at the raw bundles' 4-9 mm steps); before the ENDS chunk
        // AF_L lost 3.6 % of its mean length (2.4 % more than its chords
        // explain), iFOD2 0.25 mm more.
        const FftFile file(dir.file("f.fft"));
        const double step_mm = file.header().step * file.header().scaling;
        EXPECT_NEAR(after, target, 1e-3 * target + 0.05 * step_mm)
            << "input " << before << " mm, targets " << target << " mm, decoded " << after << " mm";
        // And against the input: chords on the cubic through its points keep
        // its length (on the polyline, iFOD2's fibers lost 0.34 mm = 0.67 step).
        EXPECT_NEAR(after, before, 1e-3 * before + 0.15 * step_mm) << "step " << step_mm << " mm";
    }
}

// Compresses a resampled tractogram and measures, fiber by fiber by brute
// force, how far the decoded lengths are from the input's: fiblet's decoder
// and the float64 reference decoder (tests/exact_decoder.hpp, the ENDS
// fraction applied as formats/fft-ends.md says), and what resampling
// itself could not keep (the tension fit's residual, formats/fft.md §5).
struct ResampledLengthChanges {
    bool resampled = false;
    double recorded = 0;  // the header's max error, mm
    double worst = 0, worst_exact = 0, unkept = 0;
};

ResampledLengthChanges measure_resampled_lengths(const std::string& tck, const std::string& fft,
                                                 const CompressOptions& o) {
    ResampledLengthChanges m;
    m.resampled = compress_file(tck, fft, o).resampled;
    if (!m.resampled) return m;
    const FftFile file(fft);
    const Resampling how = *file.resampling();
    m.recorded = double(file.header().max_error_mm) * (1 + 1e-6) + 1e-7;
    const Streamlines s = decode_fibers(file, 0, file.header().fibers);
    const std::string bytes = test::read_file(fft);
    const test::exact::Decoded exact = test::exact::decode(bytes);
    const std::string ends = test::exact::trailer_chunk(bytes, "ENDS");
    EXPECT_EQ(ends.size(), 2 * exact.fibers.size());
    TckReader in(tck);
    std::vector<Vec3f> f, target;
    for (std::size_t i = 0; in.next(f) && 2 * i + 1 < ends.size(); ++i) {
        if (f.size() < 2) continue;
        const double li = length_of(&f[0].x, f.size());
        resample_keeping_end(f, how, target);
        // What the resampling, stretched by the decoder's step, leaves of the length.
        m.unkept = std::max(m.unkept, std::fabs(how.stretch * length_of(&target[0].x, target.size()) - li));
        const std::uint64_t n = s.offsets[i + 1] - s.offsets[i];
        m.worst = std::max(m.worst, std::fabs(length_of(&s.xyz[3 * s.offsets[i]], n) - li));
        m.worst_exact = std::max(m.worst_exact, std::fabs(length_of(exact.fibers[i]) - li));
    }
    return m;
}

void expect_lengths_within_the_recorded_error(const ResampledLengthChanges& m) {
    EXPECT_LE(m.worst, m.recorded) << "a fiber's length changed by more than the recorded error (resampling kept all "
                                      "but "
                                   << m.unkept << " mm)";
    EXPECT_LE(m.worst_exact, 1.05 * m.recorded) << "float64 decode";
}

// Fiber by fiber, resampled files (iFOD2, raw and 0.1 mm bundles) at the
// defaults: the decoded length is the input's within the error the header
// records, by brute force, nothing set aside; fiblet's decoder, and the
// float64 reference decoder within 1.05x. Before the length feedback
// (encode/length_feedback.hpp) the codes' lag at block ends added up to
// 96 um on iFOD2 for 46 um recorded, and the end fraction left the raw
// bundles 0.4-0.9 mm off. With --bits auto the 0.1 mm bundles whose fibers
// 8-bit codes would zig-zag longer than the point error are written with 16-bit codes
// (encode/direction_bits.hpp): at 8 bits, cingulum-1-step0.1 was 19.3 um
// off for 4.6 um recorded (36 um before the length feedback); before the
// rounded corners and the finer step for fibers of few points
// (docs/encode.md), the raw cingulum-1 was 1.14 mm off for 0.63 mm
// recorded: fibers spaced 1.8 mm at a 3.75 mm step.
TEST(FiberEndsSharedData, ResampledLengthsWithinTheRecordedError) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    std::size_t resampled_files = 0;
    for (const std::string& tck : shared_tractograms()) {
        SCOPED_TRACE(tck);
        CompressOptions o;
        o.overwrite = true;
        o.direction_bits = std::nullopt;  // --bits auto: 16 where 8-bit codes would not keep the lengths
        const ResampledLengthChanges m = measure_resampled_lengths(tck, dir.file("f.fft"), o);
        if (!m.resampled) continue;
        ++resampled_files;
        expect_lengths_within_the_recorded_error(m);
    }
    EXPECT_GE(resampled_files, 6u);
}

// The 0.1 mm bundles whose lengths 8-bit codes keep within the recorded
// error, forced to 8 bits (the default chooses 8 for them too, but would
// hide a regression by choosing 16). Their worst fibers end on a last
// block of one or two anchors (no end fraction): before the end anchors
// were rounded to keep the length (fiber_end_encoder.hpp),
// CC_ForcepsMajor-step0.1 was 1.48 um off for 0.98 um recorded and
// CST_R-step0.1 1.88 for 1.72 (docs/encode.md). At 8 bits
// cingulum-1/2-step0.1 still miss (19.3 for 4.6, 1.94 for 1.77 um).
TEST(FiberEndsSharedData, FineStepBundlesKeepLengthsWithinTheRecordedErrorAtEightBits) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    for (const char* name : {"AF_L-step0.1.tck", "CC_ForcepsMajor-step0.1.tck", "CST_R-step0.1.tck"}) {
        const std::string tck = test::shared_data("bundles") + "/" + name;
        SCOPED_TRACE(tck);
        CompressOptions o;
        o.overwrite = true;
        o.direction_bits = 8;
        const ResampledLengthChanges m = measure_resampled_lengths(tck, dir.file("f.fft"), o);
        ASSERT_TRUE(m.resampled);
        expect_lengths_within_the_recorded_error(m);
    }
}

// Fiber by fiber, fixed-step files (not resampled: the targets are the
// input's points): the decoded length is the input polyline's within the
// error the header records, for fiblet's decoder and for the float64
// reference decoder (within 1.05x). Lengths by brute force over the decoded
// and input points. Before the tail feedback (encode/length_feedback.hpp,
// feed_back_length_tails) and the sampling step for fixed-step input, the
// decoder's tuned step (x1.0005) and the codes' lag made fibers up to
// 52 um (small-ifod1) and 83 um (small-ifod1-step0.05) longer for 5.6 and
// 2.6 um recorded. small-sdstream's smooth fibers zig-zag across the 8-bit
// code grid (54 um for 5.4 um recorded, docs/encode.md); with --bits auto
// they get 16-bit codes (encode/direction_bits.hpp), checked here too.
TEST(FiberEndsSharedData, FixedStepLengthsWithinTheRecordedError) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    std::size_t checked = 0, sixteen_bit = 0;
    for (const std::string& tck : shared_tractograms()) {
        SCOPED_TRACE(tck);
        CompressOptions o;
        o.overwrite = true;
        o.direction_bits = std::nullopt;  // --bits auto (the default's 8 bits: compress says so, CompressLengthNote)
        const CompressReport r = compress_file(tck, dir.file("f.fft"), o);
        if (r.resampled) continue;
        ++checked;
        sixteen_bit += r.header.direction_bits() == 16;
        const FftFile file(dir.file("f.fft"));
        const double recorded = double(file.header().max_error_mm) * (1 + 1e-6) + 1e-7;
        const Streamlines s = decode_fibers(file, 0, file.header().fibers);
        const test::exact::Decoded exact = test::exact::decode(test::read_file(dir.file("f.fft")));
        TckReader in(tck);
        std::vector<Vec3f> f;
        double worst = 0, worst_exact = 0;
        for (std::size_t i = 0; in.next(f); ++i) {
            if (f.size() < 2) continue;
            const double li = length_of(&f[0].x, f.size());
            const std::uint64_t n = s.offsets[i + 1] - s.offsets[i];
            ASSERT_EQ(n, f.size());
            worst = std::max(worst, std::fabs(length_of(&s.xyz[3 * s.offsets[i]], n) - li));
            const std::vector<test::exact::V3>& e = exact.fibers[i];
            ASSERT_EQ(e.size(), f.size());
            worst_exact = std::max(worst_exact, std::fabs(length_of(e) - li));
        }
        EXPECT_LE(worst, recorded) << "a fiber's length changed by more than the recorded error";
        EXPECT_LE(worst_exact, 1.05 * recorded) << "float64 decode";
    }
    EXPECT_GE(checked, 4u);      // three iFOD1 files and small-sdstream
    EXPECT_GE(sixteen_bit, 1u);  // small-sdstream
}

// Fibers of few points (the raw bundles: 20 a fiber, one 60-point block
// each) get the finest step at which every fiber keeps its block count
// (block_keeping_step): the same bytes as at the median spacing, and the
// resampled fibers follow their input's corners.
TEST(FiberEndsSharedData, FewPointFibersGetAFinerStepInTheSameBytes) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    for (const char* name : {"AF_L.tck", "CC_ForcepsMajor.tck", "CST_R.tck", "cingulum-1.tck", "cingulum-2.tck"}) {
        const std::string tck = test::shared_data("bundles") + "/" + name;
        SCOPED_TRACE(tck);
        CompressOptions o;
        o.overwrite = true;
        o.direction_bits = 8;  // fixed-size 60-point blocks (at the median step the default may choose 16)
        const CompressReport finer = compress_file(tck, dir.file("finer.fft"), o);
        o.step_mm = finer.scan.step_median;
        const CompressReport median = compress_file(tck, dir.file("median.fft"), o);
        EXPECT_LE(finer.step_mm, 0.95 * median.step_mm);
        EXPECT_EQ(finer.header.blocks, median.header.blocks);
        // The same bytes but for the block index, whose coded boxes take
        // more or fewer bytes as the points move (formats/fft-index.md).
        auto bytes_but_index = [&](const std::string& path) {
            const FftFile f(path);
            return f.file_size() - f.find_chunk(kBlockIndexTag)->payload.size();
        };
        EXPECT_EQ(bytes_but_index(dir.file("finer.fft")), bytes_but_index(dir.file("median.fft")));
        EXPECT_GT(finer.header.points, median.header.points);
    }
}

// `tckedit -minlength 100` keeps as many streamlines of the decoded file as
// of its input (MRtrix3 measures (points - 1) x step_size where a file
// declares a step: the decoded file declares one only where its input did;
// on AF_L it kept 44 of the decoded streamlines for 43 of the input when it did).
TEST(FiberEndsSharedData, TckeditMinlengthKeepsTheInputsCount) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    if (test::run_command("command -v tckedit >/dev/null").status != 0) GTEST_SKIP() << "tckedit (MRtrix3) not installed";
    test::TempDir dir;
    auto long_ones = [&](const std::string& tck) {
        const auto r = test::run_command("tckedit -quiet -force -minlength 100 " + tck + " " + dir.file("long.tck") +
                                         " 2>/dev/null && tckinfo -count " + dir.file("long.tck") + " 2>/dev/null");
        EXPECT_EQ(r.status, 0) << tck;
        const auto at = r.output.find("actual count in file:");
        return at == std::string::npos ? -1L : std::stol(r.output.substr(at + 21));
    };
    for (const std::string& tck : shared_tractograms()) {
        SCOPED_TRACE(tck);
        ASSERT_EQ(test::run_cli("compress -q --force " + tck + " -o " + dir.file("f.fft")).status, 0);
        ASSERT_EQ(test::run_cli("decompress -q --force " + dir.file("f.fft") + " -o " + dir.file("d.tck")).status, 0);
        EXPECT_EQ(long_ones(dir.file("d.tck")), long_ones(tck));
    }
}

}  // namespace
}  // namespace fiblet
