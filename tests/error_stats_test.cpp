// ErrorStats against a brute-force computation on the same samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "fiblet/error_stats.hpp"
#include "scoped_simd_loops.hpp"

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

// add_all is add() of each error in turn (bit for bit but for the sums,
// which it adds in four lanes: within rounding of a long double sum);
// copies keep counting into their own histogram (the cached page is not
// shared).
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
    long double sum = 0, sum_sq = 0;
    for (double v : e) sum += v, sum_sq += (long double)v * v;
    const double mean = double(sum / e.size()), rms = double(std::sqrt(sum_sq / e.size()));
    for (const ErrorStats* s : {&one, &all}) {
        EXPECT_NEAR(s->mean_mm(), mean, 1e-12 * mean);  // n eps: 5.5e-13
        EXPECT_NEAR(s->rms_mm(), rms, 1e-12 * rms);
    }
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

// add_all's vector loop (AVX2) and its scalar loop give the same bits, for
// calls of 1 to 13 errors (every tail of the four lanes), errors past the
// histogram included; where the CPU has no AVX2 both take the scalar loop.
TEST(ErrorStats, AddAllVectorsEqualScalarLoop) {
    std::mt19937 rng(5);
    std::gamma_distribution<double> g(2.0, 0.004);
    std::vector<double> e(3000);
    for (double& v : e) v = g(rng);
    e[100] = 5.0, e[2001] = 2.5;
    auto fill = [&](ErrorStats& s) {
        for (std::size_t i = 0, n = 1; i < e.size(); i += n, n = n % 13 + 1) s.add_all(&e[i], std::min(n, e.size() - i), i);
    };
    ErrorStats vectors, scalar;
    fill(vectors);
    {
        const test::ScopedSimdLoops loops(false);
        fill(scalar);
    }
    EXPECT_EQ(vectors.count(), scalar.count());
    EXPECT_EQ(vectors.mean_mm(), scalar.mean_mm());
    EXPECT_EQ(vectors.rms_mm(), scalar.rms_mm());
    EXPECT_EQ(vectors.max_mm(), 5.0);
    EXPECT_EQ(vectors.max_mm(), scalar.max_mm());
    EXPECT_EQ(vectors.worst_fiber(), scalar.worst_fiber());
    for (double p : {1.0, 50.0, 99.0, 99.99, 100.0}) EXPECT_EQ(vectors.percentile_mm(p), scalar.percentile_mm(p)) << p;
}

// add_all_roots of `squares` (in calls of 1 to 13, with and without the
// vector loop) against add_all of `roots`, bit for bit; squares[100] is
// 6.25 (a root past the histogram).
template <class T>
void expect_roots_added_as(const std::vector<T>& squares, const std::vector<double>& roots) {
    for (const bool vectors : {true, false}) {
        const test::ScopedSimdLoops loops(vectors);
        ErrorStats from_squares, plain;
        for (std::size_t i = 0, n = 1; i < squares.size(); i += n, n = n % 13 + 1) {
            from_squares.add_all_roots(&squares[i], std::min(n, squares.size() - i), i);
            plain.add_all(&roots[i], std::min(n, squares.size() - i), i);
        }
        EXPECT_EQ(from_squares.count(), plain.count());
        EXPECT_EQ(from_squares.mean_mm(), plain.mean_mm());
        EXPECT_EQ(from_squares.rms_mm(), plain.rms_mm());
        EXPECT_EQ(from_squares.max_mm(), 2.5);
        EXPECT_EQ(from_squares.worst_fiber(), plain.worst_fiber());
        for (double p : {1.0, 50.0, 99.0, 100.0}) EXPECT_EQ(from_squares.percentile_mm(p), plain.percentile_mm(p)) << p;
    }
}

// add_all_roots of double squared errors is add_all of their square roots
// (std::sqrt).
TEST(ErrorStats, AddAllRootsEqualsAddAllOfTheRoots) {
    std::mt19937 rng(7);
    std::gamma_distribution<double> g(2.0, 0.004);
    std::vector<double> e(3000), squares(3000);
    for (std::size_t i = 0; i < e.size(); ++i) squares[i] = g(rng) * g(rng);
    squares[100] = 6.25, squares[2001] = 0.0;  // a root past the histogram, a zero
    for (std::size_t i = 0; i < e.size(); ++i) e[i] = std::sqrt(squares[i]);
    expect_roots_added_as(squares, e);
}

// Float squares: each root is taken in float (std::sqrt of the float), then
// added as a double; it stays within a float rounding of the double root.
TEST(ErrorStats, AddAllRootsOfFloatSquaresTakesFloatRoots) {
    std::mt19937 rng(11);
    std::gamma_distribution<float> g(2.0f, 0.004f);
    std::vector<float> squares(3000);
    std::vector<double> float_roots(squares.size());
    for (float& v : squares) v = g(rng) * g(rng);
    squares[100] = 6.25f, squares[2001] = 0.0f;
    for (std::size_t i = 0; i < squares.size(); ++i) {
        float_roots[i] = double(std::sqrt(squares[i]));
        EXPECT_NEAR(float_roots[i], std::sqrt(double(squares[i])), 1e-7 * std::sqrt(double(squares[i])));
    }
    expect_roots_added_as(squares, float_roots);
}
