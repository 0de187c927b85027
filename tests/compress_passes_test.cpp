// compress reads its input in two or three passes (issue 12, class 9): an
// input edited or replaced between them makes compress fail with a clear
// error, instead of writing a file whose passes disagree (one that verify
// rejects, or worse, one that decodes to other points).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <random>
#include <string>

#include "compress/compress_stages.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"
#include "fiblet/tck.hpp"
#include "scoped_simd_loops.hpp"
#include "test_util.hpp"

using namespace fiblet;
namespace fs = std::filesystem;

namespace {

// 3000 short fibers: the scan reports progress (every 1024 fibers) mid-pass.
void write_tck(const std::string& path) {
    TckWriter w(path, {}, true);
    std::vector<Vec3f> f(20);
    for (int i = 0; i < 3000; ++i) {
        for (std::size_t k = 0; k < f.size(); ++k) f[k] = {0.1f * float(k), 0.01f * float(i), 1.0f};
        w.write(f);
    }
    w.finish();
}

// Compresses `in` to `out` on `threads` threads (1: each task in turn after
// its reading; more: the pipeline), running `edit` once, during the first
// pass (the progress callback is the hook: it runs between reads). Returns
// the error.
std::string compress_editing(const std::string& in, const std::string& out, const std::function<void()>& edit,
                             unsigned threads) {
    CompressOptions o;
    o.threads = threads;
    bool done = false;
    o.progress = [&](const char* phase, double) {
        if (!done && std::strcmp(phase, "scan") == 0) edit(), done = true;
    };
    try {
        compress_file(in, out, o);
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), Errc::io) << e.what();
        return e.what();
    }
    return "no error";
}

// Overwrites 4 bytes in place near the end of the data (a coordinate), size unchanged.
void poke(const std::string& path, bool keep_mtime) {
    struct stat st {};
    ASSERT_EQ(::stat(path.c_str(), &st), 0);
    const int fd = ::open(path.c_str(), O_WRONLY);
    ASSERT_GE(fd, 0);
    const float v = 7.5f;
    ASSERT_EQ(::pwrite(fd, &v, 4, st.st_size - 100), 4);
    ::close(fd);
    if (keep_mtime) {  // an edit the size and time checks cannot see: only the bytes differ
        const struct timespec times[2] = {st.st_atim, st.st_mtim};
        ASSERT_EQ(::utimensat(AT_FDCWD, path.c_str(), times, 0), 0);
    }
}

}  // namespace

TEST(CompressPasses, AnInputEditedInPlaceIsRefused) {
    for (unsigned threads : {1u, 2u})
        for (bool keep_mtime : {false, true}) {
            SCOPED_TRACE(threads);
            test::TempDir dir;
            write_tck(dir.file("in.tck"));
            const std::string what = compress_editing(dir.file("in.tck"), dir.file("out.fft"),
                                                      [&] { poke(dir.file("in.tck"), keep_mtime); }, threads);
            EXPECT_NE(what.find("changed while it was being read"), std::string::npos) << what;
            EXPECT_NE(what.find(keep_mtime ? "other bytes" : "modification time"), std::string::npos) << what;
            EXPECT_FALSE(fs::exists(dir.file("out.fft")));
            EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
        }
}

TEST(CompressPasses, AnInputReplacedOrGrownIsRefused) {
    for (unsigned threads : {1u, 2u}) {
        SCOPED_TRACE(threads);
        test::TempDir dir;
        write_tck(dir.file("in.tck"));
        test::write_three_fiber_tck(dir.file("other.tck"));
        std::string what = compress_editing(
            dir.file("in.tck"), dir.file("out.fft"), [&] { fs::rename(dir.file("other.tck"), dir.file("in.tck")); },
            threads);
        EXPECT_NE(what.find("another file now has its name"), std::string::npos) << what;
        EXPECT_FALSE(fs::exists(dir.file("out.fft")));

        write_tck(dir.file("grown.tck"));
        what = compress_editing(
            dir.file("grown.tck"), dir.file("out.fft"),
            [&] {
                std::FILE* f = std::fopen(dir.file("grown.tck").c_str(), "ab");
                std::fputs("appended", f);
                std::fclose(f);
            },
            threads);
        EXPECT_NE(what.find("changed while it was being read"), std::string::npos) << what;
        EXPECT_FALSE(fs::exists(dir.file("out.fft")));
    }
}

TEST(CompressPasses, AnUntouchedInputCompressesAsBefore) {
    for (unsigned threads : {1u, 2u}) {
        test::TempDir dir;
        write_tck(dir.file("in.tck"));
        EXPECT_EQ(compress_editing(dir.file("in.tck"), dir.file("out.fft"), [] {}, threads), "no error") << threads;
        EXPECT_TRUE(fs::exists(dir.file("out.fft"))) << threads;
    }
}

TEST(CompressPasses, AnInputCutWhileReadIsNamedAsChangedNotAsTruncated) {
    test::TempDir dir;
    write_tck(dir.file("in.tck"));
    TckReader reader(dir.file("in.tck"), {.chunk_bytes = 4096});  // many reads: the cut lands between two
    std::vector<Vec3f> fiber;
    ASSERT_TRUE(reader.next(fiber));
    fs::resize_file(dir.file("in.tck"), fs::file_size(dir.file("in.tck")) / 2);
    try {
        while (reader.next(fiber)) {
        }
        FAIL() << "read to the end of a file cut in half";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), Errc::io) << e.what();
        EXPECT_NE(std::string(e.what()).find("changed while it was being read"), std::string::npos) << e.what();
    }
}

// The report times each stage (CompressTimings: what --json prints as
// "timings"). On one thread the stages do not overlap: their sum is at most
// the run's time, and every stage that has work to do takes some.
TEST(CompressPasses, TheStagesAreTimedWithinTheRunsTime) {
    test::TempDir dir;
    write_tck(dir.file("in.tck"));
    CompressOptions o;
    o.threads = 1;
    const CompressReport r = compress_file(dir.file("in.tck"), dir.file("out.fft"), o);
    const CompressTimings& t = r.timings;
    for (const double s : {t.read, t.scan, t.tune, t.encode, t.metrics, t.index, t.write}) EXPECT_GT(s, 0.0);
    EXPECT_LE(t.total(), r.seconds);
    // No index asked: no time in it.
    o.block_index = false;
    o.overwrite = true;
    EXPECT_EQ(compress_file(dir.file("in.tck"), dir.file("out.fft"), o).timings.index, 0.0);
}

// The median segment length, from fibers of one repeated length (runs of
// one bin), of scattered lengths, of lengths below the histogram's range
// and of none, added to two histograms then merged: the bin holding the
// sorted lengths' median, within the bins' 1.2e-4 relative width. Odd
// trials spread the lengths from micrometres to the float range's end
// (a histogram that stopped at 2 m once made 100 m segments a 2 m step).
TEST(CompressScan, TheMedianSegmentLengthIsTheSortedLengthsMedian) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> spread(0.01, 3.0), jitter(-1e-6, 1e-6), exponent(-19.0, 38.5);
    for (int trial = 0; trial < 40; ++trial) {
        SCOPED_TRACE(trial);
        const bool wide = trial % 2;
        auto draw = [&] { return wide ? std::min(std::pow(10.0, exponent(rng)), 3.4e38) : spread(rng); };
        detail::LengthHistogram a, b, scalar;
        std::vector<double> all;
        for (int fiber = 0; fiber < 12; ++fiber) {
            std::vector<double> lengths;
            const double step = draw();
            const int kind = int(rng() % 4), n = int(rng() % 300);
            for (int k = 0; k < n; ++k)
                lengths.push_back(kind == 0 ? step : kind == 1 ? step * (1 + jitter(rng)) : kind == 2 ? draw() : 1e-9);
            (fiber % 2 ? a : b).add(lengths);
            {
                const test::ScopedSimdLoops loops(false);  // the AVX2 runs' check against the scalar loop's
                scalar.add(lengths);
            }
            all.insert(all.end(), lengths.begin(), lengths.end());
        }
        a.merge(b);
        EXPECT_EQ(a.median(), scalar.median());
        if (all.empty()) continue;
        std::sort(all.begin(), all.end());
        const double median = all[(all.size() - 1) / 2], got = a.median();
        if (float(median) < 0x1p-20f) EXPECT_EQ(got, 0.0);
        else EXPECT_NEAR(got, median, 1.3e-4 * median) << all.size() << " lengths";
    }
}

// Pass 1's bounds: the AVX2 loop and the scalar loop against a brute
// force in double, at every length around the vector width, with NaN
// coordinates left out and zero bounds +0 whichever zero came first.
TEST(CompressScan, BoundsOfEveryLengthLeaveOutNaNAndGiveZeroAsPlusZero) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-50.0f, 50.0f);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (std::size_t n = 1; n <= 40; ++n) {
        for (int trial = 0; trial < 6; ++trial) {
            std::vector<Vec3f> fiber(n);
            for (Vec3f& p : fiber) p = {u(rng), u(rng), u(rng)};
            if (trial == 1) fiber[n / 2].y = nan;
            if (trial == 2)  // zeros of both signs as the lower x and upper y bounds
                for (std::size_t k = 0; k < n; ++k) fiber[k].x = std::fabs(fiber[k].x), fiber[k].y = -std::fabs(fiber[k].y);
            if (trial == 2) fiber[0].x = -0.0f, fiber[n - 1].x = 0.0f, fiber[n / 3].y = -0.0f, fiber[n - 1].y = 0.0f;
            double want_min[3], want_max[3];
            for (int a = 0; a < 3; ++a) want_min[a] = INFINITY, want_max[a] = -INFINITY;
            for (const Vec3f& p : fiber)
                for (int a = 0; a < 3; ++a) {
                    const double v = a == 0 ? p.x : a == 1 ? p.y : p.z;
                    if (std::isnan(v)) continue;
                    want_min[a] = std::min(want_min[a], v), want_max[a] = std::max(want_max[a], v);
                }
            for (bool avx2 : {true, false}) {
                double min[3] = {INFINITY, INFINITY, INFINITY}, max[3] = {-INFINITY, -INFINITY, -INFINITY};
                {
                    const test::ScopedSimdLoops loops(avx2);
                    detail::add_bounds(fiber, min, max);
                }
                for (int a = 0; a < 3; ++a) {
                    EXPECT_EQ(min[a], want_min[a]) << n << " " << trial << " " << avx2 << " axis " << a;
                    EXPECT_EQ(max[a], want_max[a]) << n << " " << trial << " " << avx2 << " axis " << a;
                    if (min[a] == 0) {
                        EXPECT_FALSE(std::signbit(min[a])) << n << " " << trial << " " << avx2;
                    }
                    if (max[a] == 0) {
                        EXPECT_FALSE(std::signbit(max[a])) << n << " " << trial << " " << avx2;
                    }
                }
            }
        }
    }
}
