// ErrorStats against a brute-force computation on the same samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "fiblet/error_stats.hpp"

using namespace fiblet;

TEST(ErrorStats, MatchesBruteForce) {
    std::mt19937 rng(9);
    std::gamma_distribution<double> g(2.0, 0.002);  // mm, like codec errors
    std::vector<double> all;
    ErrorStats a, b;
    for (int i = 0; i < 100000; ++i) {
        const double e = g(rng);
        all.push_back(e);
        (i % 3 ? a : b).add(e, std::uint64_t(i / 100));
    }
    a.merge(b);
    std::vector<double> sorted = all;
    std::sort(sorted.begin(), sorted.end());
    double sum = 0, sq = 0;
    for (double e : all) sum += e, sq += e * e;
    const auto worst = std::max_element(all.begin(), all.end()) - all.begin();
    EXPECT_EQ(a.count(), all.size());
    EXPECT_DOUBLE_EQ(a.max_mm(), sorted.back());
    EXPECT_NEAR(a.mean_mm(), sum / double(all.size()), 1e-12);
    EXPECT_NEAR(a.rms_mm(), std::sqrt(sq / double(all.size())), 1e-12);
    EXPECT_EQ(a.worst_fiber(), std::uint64_t(worst / 100));
    for (double p : {50.0, 95.0, 99.0}) {
        const double exact = sorted[std::size_t(std::ceil(p / 100 * double(all.size()))) - 1];
        EXPECT_NEAR(a.percentile_mm(p), exact, 1e-5 + 1e-12) << p;  // 0.01 µm bins
    }
}

// add_all is add() of each error in turn, bit for bit; copies keep counting
// into their own histogram (the cached page is not shared).
TEST(ErrorStats, AddAllEqualsAddAndCopiesAreIndependent) {
    std::mt19937 rng(3);
    std::gamma_distribution<double> g(2.0, 0.004);
    std::vector<double> e(5000);
    for (double& v : e) v = g(rng);
    e[17] = 3.0;  // past the histogram
    ErrorStats one, all;
    for (std::size_t i = 0; i < e.size(); ++i) one.add(e[i], i / 50);
    for (std::size_t i = 0; i < e.size(); i += 50) all.add_all(&e[i], std::min<std::size_t>(50, e.size() - i), i / 50);
    EXPECT_EQ(one.count(), all.count());
    EXPECT_EQ(one.mean_mm(), all.mean_mm());
    EXPECT_EQ(one.rms_mm(), all.rms_mm());
    EXPECT_EQ(one.max_mm(), all.max_mm());
    EXPECT_EQ(one.worst_fiber(), all.worst_fiber());
    for (double p : {1.0, 50.0, 99.0, 99.99}) EXPECT_EQ(one.percentile_mm(p), all.percentile_mm(p)) << p;
    ErrorStats x;
    x.add(0.001, 0);
    ErrorStats y = x;
    for (int i = 0; i < 3; ++i) y.add(0.002, 1);
    EXPECT_NEAR(x.percentile_mm(100), 0.001, 1e-5);
    EXPECT_NEAR(y.percentile_mm(50), 0.002, 1e-5);
    EXPECT_EQ(x.count(), 1u);
}
