// formats/resample.md implemented here from the page alone (no library code
// read or called but the function under test), and compared with fiblet's
// resampling bit for bit: the page is precise enough for a reader to rebuild
// the encoder's target points (and so check a resampled file's recorded error).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "fiblet/resample.hpp"
#include "test_util.hpp"

namespace fiblet {
namespace {

struct D3 {
    double x, y, z;
};
D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
D3 operator*(D3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
double norm(D3 a) { return std::sqrt(dot(a, a)); }
D3 widen(Vec3f p) { return {p.x, p.y, p.z}; }
Vec3f narrow(D3 p) { return {float(p.x), float(p.y), float(p.z)}; }

double length_of(const std::vector<Vec3f>& l) {
    double s = 0;
    for (std::size_t k = 1; k < l.size(); ++k) s += norm(widen(l[k]) - widen(l[k - 1]));
    return s;
}

// §3: the chord walk over straight pieces.
struct Walk {
    D3 q;
    double step;
    std::vector<Vec3f> out;
    void piece(D3 a, D3 b) {
        const D3 d = b - a;
        const double qa = dot(d, d);
        if (!(qa > 0)) return;
        while (dot(b - q, b - q) >= step * step) {
            const D3 f = a - q;
            const double qb = 2 * dot(f, d), qc = dot(f, f) - step * step;
            const double disc = std::max(qb * qb - 4 * qa * qc, 0.0);
            const double t = std::clamp((-qb + std::sqrt(disc)) / (2 * qa), 0.0, 1.0);
            q = a + d * t;
            out.push_back(narrow(q));
        }
    }
    // §2: a Hermite piece of chord length L as N straight pieces.
    void hermite(D3 p0, D3 m0, D3 p1, D3 m1, double L) {
        const std::size_t n = std::size_t(std::clamp(std::ceil(16 * L / step), 1.0, 256.0));
        D3 from = p0;
        for (std::size_t k = 1; k <= n; ++k) {
            const double t = double(k) / double(n), t2 = t * t, t3 = t2 * t;
            const D3 to = k == n ? p1
                                 : (p0 * (2 * t3 - 3 * t2 + 1) + m0 * (L * (t3 - 2 * t2 + t))) +
                                       (p1 * (3 * t2 - 2 * t3) + m1 * (L * (t3 - t2)));
            piece(from, to);
            from = to;
        }
    }
};

// §1-§3 at tension tau.
std::vector<Vec3f> targets_at(const std::vector<Vec3f>& in, double step, double tau) {
    std::vector<D3> p;
    for (const Vec3f& v : in)
        if (p.empty() || dot(widen(v) - p.back(), widen(v) - p.back()) > 0) p.push_back(widen(v));
    Walk w{p[0], step, {narrow(p[0])}};
    const std::size_t n = p.size();
    if (n == 2) w.piece(p[0], p[1]);
    if (n >= 3) {
        std::vector<double> d(n - 1);
        std::vector<D3> u(n - 1), m(n);
        for (std::size_t i = 0; i + 1 < n; ++i) d[i] = norm(p[i + 1] - p[i]), u[i] = (p[i + 1] - p[i]) * (1 / d[i]);
        for (std::size_t i = 1; i + 1 < n; ++i) m[i] = (u[i - 1] * d[i] + u[i] * d[i - 1]) * (1 / (d[i - 1] + d[i]));
        m[0] = u[0] * 2 - m[1];
        m[n - 1] = u[n - 2] * 2 - m[n - 2];
        const double c = 2 * step;
        for (std::size_t i = 0; i + 1 < n; ++i) {
            if (d[i] > 2 * c) {
                const D3 a = p[i] + u[i] * c, b = p[i + 1] - u[i] * c;
                w.hermite(p[i], m[i] * tau, a, u[i] * tau, c);
                w.piece(a, b);
                w.hermite(b, u[i] * tau, p[i + 1], m[i + 1] * tau, c);
            } else {
                w.hermite(p[i], (u[i] + (m[i] - u[i])) * tau, p[i + 1], (u[i] + (m[i + 1] - u[i])) * tau, d[i]);
            }
        }
    }
    if (in.size() >= 2 && norm(widen(in.back()) - widen(w.out.back())) > 1e-3 * step) w.out.push_back(in.back());
    return w.out;
}

// §4: the tension.
double tension_of(const std::vector<Vec3f>& in, double step, double s) {
    const double target = length_of(in), tol = 1e-3 * step;
    auto E = [&](double tau) { return s * length_of(targets_at(in, step, tau)) - target; };
    double best_t = 1, best = E(1);
    if (!(std::fabs(best) > tol)) return 1;
    auto consider = [&](double t, double e) {
        if (std::fabs(e) < std::fabs(best)) best = e, best_t = t;
    };
    const bool short_ = best < 0;
    double lo = 1, e_lo = best, hi = 1, e_hi = best;
    bool found = false;
    for (double t : short_ ? std::vector<double>{1.75, 2.5, 4} : std::vector<double>{0.5, 0}) {
        const double e = E(t);
        consider(t, e);
        found = (e < 0) != short_ || e == 0;
        if (e < 0) lo = t, e_lo = e;
        else hi = t, e_hi = e;
        if (found) break;
    }
    auto quantized = [](double t) { return std::round(t * 8192) / 8192; };
    if (!found || !(std::fabs(best) > tol)) return quantized(best_t);
    int last = 0;  // 1: lo replaced at the previous step, -1: hi
    for (int i = 0; i < 16 && std::fabs(best) > tol; ++i) {
        const double t = (lo * e_hi - hi * e_lo) / (e_hi - e_lo);
        const double e = E(t);
        consider(t, e);
        if ((e < 0) == (e_lo < 0)) {
            lo = t, e_lo = e;
            if (last == 1) e_hi *= 0.5;
            last = 1;
        } else {
            hi = t, e_hi = e;
            if (last == -1) e_lo *= 0.5;
            last = -1;
        }
    }
    return quantized(best_t);
}

bool same(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3f)) == 0;
}

void expect_spec_matches(const std::vector<std::vector<Vec3f>>& fibers, double step, double stretch, const char* what) {
    const Resampling how{.step_mm = step, .curve = ResampleCurve::rounded_keeping_length, .stretch = stretch};
    std::size_t differ = 0, kept_ends = 0;
    for (const auto& f : fibers) {
        if (f.empty()) continue;
        std::vector<Vec3f> got;
        kept_ends += resample_keeping_end(f, how, got);
        differ += !same(got, targets_at(f, step, tension_of(f, step, stretch)));
    }
    EXPECT_EQ(differ, 0u) << what << ": fibers whose targets differ from formats/resample.md's";
    EXPECT_GT(kept_ends, 0u) << what;
}

}  // namespace

TEST(ResampleSpec, SharedTractogramsMatchThePageBitForBit) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    for (const char* name : {"small-ifod2.tck", "small-sdstream.tck"}) {
        auto fibers = test::read_tck_fibers(test::shared_data(name));
        fibers.resize(std::min<std::size_t>(fibers.size(), 300));
        expect_spec_matches(fibers, 0.5, 1.00025, name);
        expect_spec_matches(fibers, 0.37, 1.0, name);
    }
}

// Sparse and uneven input: long straight segments (the rounded corners of
// §2), repeated points, two-point and one-point fibers.
TEST(ResampleSpec, SparseUnevenInputMatchesThePageBitForBit) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1), len(0.05, 9);
    std::vector<std::vector<Vec3f>> fibers{{{1, 2, 3}}, {{0, 0, 0}, {3.3f, 0.1f, 0}}};
    for (int k = 0; k < 60; ++k) {
        std::vector<Vec3f> f{{float(10 * u(rng)), float(10 * u(rng)), float(10 * u(rng))}};
        for (int i = 0; i < 5 + k; ++i) {
            const Vec3f q = f.back();
            const double l = len(rng);
            f.push_back({float(q.x + l * u(rng)), float(q.y + l * u(rng)), float(q.z + l * u(rng))});
            if (i % 7 == 3) f.push_back(f.back());  // a repeated point
        }
        fibers.push_back(f);
    }
    expect_spec_matches(fibers, 0.5, 1.0, "sparse");
    expect_spec_matches(fibers, 2.0, 1.0005, "sparse, 2 mm");
}

}  // namespace fiblet
