// Stress tests of the decoder-independent error: inputs built to make the
// first frame of blocks ill-conditioned (first segments within 1 degree of
// the helper vector ±C), loops, a 10^5-point fiber. Each is compressed with
// the default settings and decoded by the float64 reference decoder
// (exact_decoder.hpp) and by fiblet's decoders: both must stay within 1.05x
// the max error the header records.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "exact_error.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/direction_code.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

namespace fiblet {
namespace {

using Fiber = std::vector<Vec3f>;
using D3 = test::exact::V3;

constexpr double kDecoderSlack = 1.05;

D3 helper() { return {kFrameHelper[0], kFrameHelper[1], kFrameHelper[2]}; }

// A unit vector at `angle` (radians) from unit `axis`, towards a random side.
D3 tilted(D3 axis, double angle, std::mt19937& rng) {
    std::normal_distribution<double> n;
    D3 side = test::exact::cross(axis, D3{n(rng), n(rng), n(rng)});
    side = test::exact::unit(side);
    return std::cos(angle) * axis + std::sin(angle) * side;
}

// A straight fiber of `points` along unit `dir` at `step` mm from `start`.
Fiber straight_fiber(D3 start, D3 dir, std::size_t points, double step) {
    Fiber f;
    for (std::size_t i = 0; i < points; ++i) {
        const D3 p = start + (double(i) * step) * dir;
        f.push_back({float(p.x), float(p.y), float(p.z)});
    }
    return f;
}

// A fiber from `start` whose first segment runs along `dir0`, then bends
// on a circle of radius `radius` mm (in a random plane containing dir0):
// the rest of the block strays from the first axis, which is where a turn
// of the first frame about that axis shows.
Fiber bending_fiber(D3 start, D3 dir0, double radius, std::size_t points, double step, std::mt19937& rng) {
    std::normal_distribution<double> n;
    const D3 normal = test::exact::unit(test::exact::cross(dir0, D3{n(rng), n(rng), n(rng)}));
    Fiber f;
    D3 p = start, d = dir0;
    const double turn = step / radius;  // radians per step
    for (std::size_t i = 0; i < points; ++i) {
        f.push_back({float(p.x), float(p.y), float(p.z)});
        p = p + step * d;
        const D3 bent = test::exact::cross(normal, d);  // d turns about `normal`
        d = test::exact::unit(std::cos(turn) * d + std::sin(turn) * bent);
    }
    return f;
}

struct Outcome {
    test::ExactMeasurement m;
};

Outcome compress_and_measure(const std::vector<Fiber>& fibers, const std::string& name) {
    const test::TempDir dir;
    const std::string tck = dir.file(name + ".tck"), fft = dir.file(name + ".fft");
    {
        TckWriter w(tck, {}, true);
        for (const Fiber& f : fibers) w.write(f);
        w.finish();
    }
    CompressOptions o;
    o.overwrite = true;
    compress_file(tck, fft, o);
    return {test::measure_exact(fft, tck)};
}

void expect_within_header(const Outcome& o, const char* what) {
    ASSERT_GT(o.m.exact.points, 0u);
    ASSERT_GT(o.m.header_max_mm, 0.0);
    EXPECT_LE(o.m.exact.max_mm, kDecoderSlack * o.m.header_max_mm) << what << ": float64 decode";
    EXPECT_LE(o.m.fiblet.max_mm, kDecoderSlack * o.m.header_max_mm) << what << ": fiblet's decoder";
    EXPECT_LE(o.m.original.max_mm, kDecoderSlack * o.m.header_max_mm) << what << ": the original decoder's frames";
}

// The fiber turned rigidly about its first point so that its first
// segment runs along `to` (Rodrigues' formula).
Fiber turned(const Fiber& f, D3 to) {
    const D3 from = test::exact::unit(D3{f[1].x - f[0].x, f[1].y - f[0].y, f[1].z - f[0].z});
    const D3 k = test::exact::cross(from, to);
    const double s = std::sqrt(test::exact::dot(k, k)), c = test::exact::dot(from, to);
    const D3 axis = s > 0 ? (1 / s) * k : D3{1, 0, 0};
    Fiber out;
    for (const Vec3f& q : f) {
        const D3 v{q.x - f[0].x, q.y - f[0].y, q.z - f[0].z};
        const D3 r = c * v + s * test::exact::cross(axis, v) + (1 - c) * test::exact::dot(axis, v) * axis;
        out.push_back({float(f[0].x + r.x), float(f[0].y + r.y), float(f[0].z + r.z)});
    }
    return out;
}

// Every fiber starts within 1 degree of +C or -C and bends away; 60-point
// fibers, so every block starts ill-conditioned. The same fibers turned
// so that they start far from ±C are the control: the robust encoding
// must keep the near-helper case close. Measured: max 1.98 vs 1.37 um
// (1.45x), mean within 10 %; without the anchor conditioning and robust
// search the header max is 12.5 um (9x) and the mean 1.4x.
TEST(ExactStress, FirstSegmentsWithinOneDegreeOfTheHelper) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Fiber> fibers, control;
    for (int i = 0; i < 600; ++i) {
        const D3 axis = (i % 2 ? -1.0 : 1.0) * helper();
        const D3 dir0 = tilted(axis, u(rng) * M_PI / 180, rng);
        const D3 start{u(rng) * 100 - 50, u(rng) * 100 - 50, u(rng) * 100 - 50};
        fibers.push_back(bending_fiber(start, dir0, 5 + 20 * u(rng), 60, 0.1, rng));
        control.push_back(turned(fibers.back(), tilted(axis, M_PI / 2, rng)));  // 90 degrees off ±C
    }
    const Outcome o = compress_and_measure(fibers, "near-helper");
    expect_within_header(o, "first segments along ±C");
    const Outcome c = compress_and_measure(control, "control");
    expect_within_header(c, "control");
    EXPECT_LT(o.m.header_max_mm, 1.6 * c.m.header_max_mm);
    // Measured: 1.098x with greedy aiming, 1.105x with the default's lookahead
    // (which lowers both means, the control's by 1.5 %, these by 0.9 %).
    EXPECT_LT(o.m.exact.mean_mm(), 1.12 * c.m.exact.mean_mm());
}

// Fibers whose first segments run exactly along +C and -C (straight, and
// bending away after the first segment), at 0.1 mm and 2 mm steps: where
// fiblet's frame would take the fallback helper, which the original decoder
// lacks (formats/fft.md §4), the encoder moves the second anchor off the
// fallback's cone, so the original decoder's frames decode every block
// within the recorded error too (before: 54 um off on the 2 mm lines).
TEST(ExactStress, FirstSegmentsAlongTheHelper) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0, 1);
    for (double step : {0.1, 2.0}) {
        std::vector<Fiber> fibers;
        for (int i = 0; i < 40; ++i) {
            const D3 axis = (i % 2 ? -1.0 : 1.0) * helper();
            const D3 start{u(rng) * 100 - 50, u(rng) * 100 - 50, u(rng) * 100 - 50};
            fibers.push_back(i % 4 < 2 ? straight_fiber(start, axis, 130, step)
                                       : bending_fiber(start, axis, 40 * step * (1 + u(rng)), 130, step, rng));
        }
        const Outcome o = compress_and_measure(fibers, "along-helper");
        expect_within_header(o, step < 1 ? "along ±C, 0.1 mm" : "along ±C, 2 mm");
    }
}

// Tight loops (radius 1 to 3 mm, several turns), the longest block of a
// loop sweeping far around its first axis.
TEST(ExactStress, Loops) {
    std::mt19937 rng(12);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Fiber> fibers;
    for (int i = 0; i < 200; ++i) {
        const D3 dir0 = i % 4 == 0 ? tilted(helper(), u(rng) * M_PI / 180, rng) : tilted({1, 0, 0}, u(rng) * M_PI, rng);
        const D3 start{u(rng) * 80 - 40, u(rng) * 80 - 40, u(rng) * 80 - 40};
        const double radius = 1 + 2 * u(rng);
        const auto points = std::size_t(3 * 2 * M_PI * radius / 0.1);  // three turns
        fibers.push_back(bending_fiber(start, dir0, radius, points, 0.1, rng));
    }
    expect_within_header(compress_and_measure(fibers, "loops"), "loops");
}

// One fiber of 10^5 points (a persistent random walk, 10 m long) next to a
// few that set a brain-sized box.
TEST(ExactStress, HundredThousandPointFiber) {
    std::mt19937 rng(13);
    std::normal_distribution<double> n;
    Fiber f;
    D3 p{0, 0, 0}, d = test::exact::unit({1, 1, 0});
    for (int i = 0; i < 100000; ++i) {
        f.push_back({float(p.x), float(p.y), float(p.z)});
        p = p + 0.1 * d;
        d = test::exact::unit(d + 0.02 * D3{n(rng), n(rng), n(rng)});
    }
    const Outcome o = compress_and_measure({f}, "long");
    EXPECT_EQ(o.m.exact.points, 100000u);
    expect_within_header(o, "10^5-point fiber");
}

}  // namespace
}  // namespace fiblet
