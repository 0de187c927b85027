// Bounded memory, CI-sized (scripts/bench_memory.sh runs the >= 5 GB case):
// the CLI's peak RSS (test::run_cli_peak) on a ~200 MB tractogram stays under 256 MB and
// grows from a ~40 MB one by no more than the per-fiber tables (12 bytes
// per fiber) and one decode chunk, i.e. it does not grow with the size of
// the data; and encoding threads do not multiply it.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "fiblet/error_stats.hpp"
#include "fiblet/tck.hpp"
#include "cli_runner.hpp"
#include "test_util.hpp"

using namespace fiblet;

namespace {

using test::kSanitized;

constexpr double kBoundMb = 256;

// Runs the CLI; returns its peak RSS in MB, or -1 if it did not exit with 0.
double peak_rss_mb(const std::vector<std::string>& args) {
    const test::PeakRun r = test::run_cli_peak(args);
    return r.status == 0 ? r.peak_mb : -1;
}

// Smooth random walks at a fixed 0.1 mm step, 40..119 points each, until
// about `bytes` of .tck; returns the number of fibers.
std::uint64_t write_tractogram(const std::string& path, double bytes, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    TckWriter w(path, {}, true);
    std::vector<Vec3f> f;
    std::uint64_t fibers = 0;
    for (double written = 0; written < bytes; ++fibers) {
        f.resize(40 + rng() % 80);
        double p[3] = {30 * u(rng), 30 * u(rng), 30 * u(rng)}, d[3] = {u(rng), u(rng), u(rng) + 1e-6};
        for (auto& q : f) {
            q = {float(p[0]), float(p[1]), float(p[2])};
            double n = 0;
            for (int a = 0; a < 3; ++a) d[a] += 0.02 * u(rng) - 0.001 * p[a], n += d[a] * d[a];
            for (int a = 0; a < 3; ++a) d[a] /= std::sqrt(n), p[a] += 0.1 * d[a];
        }
        w.write(f);
        written += 12.0 * double(f.size() + 1);
    }
    w.finish();
    return fibers;
}

struct Peaks {
    double compress, decompress, stats;
};

Peaks measure(const test::TempDir& dir, const std::string& name) {
    const std::string tck = dir.file(name + ".tck"), fft = dir.file(name + ".fft"), back = dir.file(name + "-back.tck");
    Peaks p{};
    p.compress = peak_rss_mb({"compress", "-q", "-j", "2", tck, "-o", fft});
    p.decompress = peak_rss_mb({"decompress", "-q", fft, "-o", back});
    p.stats = peak_rss_mb({"stats", "-q", fft, "-r", tck});
    std::remove(back.c_str());
    return p;
}

}  // namespace

TEST(Memory, PeakRssDoesNotGrowWithTheInput) {
    if (kSanitized) GTEST_SKIP() << "RSS is meaningless under AddressSanitizer";
    test::TempDir dir;
    const std::uint64_t small_fibers = write_tractogram(dir.file("small.tck"), 40e6, 1);
    const std::uint64_t large_fibers = write_tractogram(dir.file("large.tck"), 200e6, 2);
    const Peaks small = measure(dir, "small"), large = measure(dir, "large");
    for (const auto& [what, s, l] : {std::tuple{"compress", small.compress, large.compress},
                                     std::tuple{"decompress", small.decompress, large.decompress},
                                     std::tuple{"stats", small.stats, large.stats}}) {
        SCOPED_TRACE(what);
        ASSERT_GT(s, 0) << "the command failed";
        ASSERT_GT(l, 0) << "the command failed";
        EXPECT_LE(l, kBoundMb);
        // 5x the data: at most the per-fiber tables (12 B per fiber) more, and
        // one more decode chunk (65536 blocks of up to 60 points: 45 MB of
        // floats, reallocated when a later chunk holds more points than the
        // first) that a small file may not reach. Holding the data would add
        // 160 MB or more.
        const double per_fiber_mb = 12.0 * double(large_fibers - small_fibers) / (1 << 20);
        EXPECT_LE(l, s + per_fiber_mb + 48) << "small " << s << " MB, large " << l << " MB";
        RecordProperty(std::string(what) + "_small_mb", std::to_string(s));
        RecordProperty(std::string(what) + "_large_mb", std::to_string(l));
    }
}

TEST(Memory, EncodingThreadsDoNotMultiplyIt) {
    if (kSanitized) GTEST_SKIP() << "RSS is meaningless under AddressSanitizer";
    test::TempDir dir;
    write_tractogram(dir.file("in.tck"), 10e6, 3);
    const double two = peak_rss_mb({"compress", "-q", "-j", "2", dir.file("in.tck"), "-o", dir.file("a.fft")});
    const double many = peak_rss_mb({"compress", "-q", "-j", "64", dir.file("in.tck"), "-o", dir.file("b.fft")});
    ASSERT_GT(two, 0);
    ASSERT_GT(many, 0);
    // 62 more threads: their batch slices are the same data split finer; only
    // their stacks and small per-thread state are extra.
    EXPECT_LE(many, two + 40) << "-j 2: " << two << " MB, -j 64: " << many << " MB";
}

TEST(Memory, PagedErrorHistogramGivesTheSortedPercentiles) {
    // Errors spread over many histogram pages (0..3 mm), against sorting.
    std::mt19937_64 rng(7);
    std::exponential_distribution<double> tail(1 / 0.02);
    std::vector<double> all;
    ErrorStats a, b, merged;
    for (int i = 0; i < 200000; ++i) {
        const double e = i % 100 == 0 ? 3.0 * double(rng() % 1000) / 1000 : tail(rng);
        all.push_back(e);
        (i % 3 ? a : b).add(e, std::uint64_t(i));
    }
    merged.merge(a);
    merged.merge(b);
    std::sort(all.begin(), all.end());
    for (double p : {1.0, 50.0, 90.0, 99.0, 99.9}) {
        const double exact = all[std::size_t(std::ceil(p / 100 * double(all.size()))) - 1];
        // Bins are 0.01 um wide: the percentile is the upper edge of the exact value's bin.
        if (exact < 2.0) {
            EXPECT_NEAR(merged.percentile_mm(p), exact, 1e-5) << "p" << p;
        }
    }
    EXPECT_EQ(merged.count(), all.size());
    EXPECT_DOUBLE_EQ(merged.max_mm(), all.back());
}
