// Numerical stress tests of the encoder: extreme inputs, every search
// effort, decoded by the scalar reference decoder. Each case asserts that
// every decoded point is finite and within the a-priori bound derived in
// formats/error-bound.md (tests/error_bound.hpp), which depends only on the
// input polyline and the encoding's parameters.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <random>

#include "encode/nearest_code_lut.hpp"
#include "error_bound.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/resample.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

using namespace fiblet;

namespace {

using Fiber = std::vector<Vec3f>;

// The searches every case runs: greedy, greedy + retry (every block is
// retried), the default's lookahead + retry, beams of two radii.
std::vector<std::pair<const char*, SearchOptions>> searches() {
    return {{"greedy", {1, 1, 0, 1, 0}},
            {"greedy+retry", {1, 1, 8, 1, 1e-9}},
            {"lookahead2+retry", {1, 1, 8, 1, 1e-9, 2}},
            {"beam4", {4, 1, 0, 1, 0}},
            {"beam8r2+retry", {8, 2, 16, 3, 1e-9}}};
}

// A header as the compress pipeline makes it: the bounding box normalized
// into the unit cube, `step_mm` times `scale` as the decoder step.
FftHeader header_for(const std::vector<Fiber>& fibers, unsigned bits, double ratio, double step_mm, double scale = 1.0,
                     std::uint32_t points_per_block = 0) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (const Fiber& f : fibers)
        for (const Vec3f& p : f) {
            const double c[3] = {p.x, p.y, p.z};
            for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
        }
    FftHeader h;
    h.version = bits == 16 ? kFft16Version : kFftVersion;
    h.points_per_block = points_per_block ? points_per_block : (bits == 16 ? kDefaultPointsPerBlock16 : kDefaultPointsPerBlock);
    double extent = 0;
    for (int a = 0; a < 3; ++a) h.offset[a] = float(-0.5 * (lo[a] + hi[a])), extent = std::max(extent, hi[a] - lo[a]);
    h.scaling = extent > 0 ? float(extent * (1 + 1e-6)) : 1.0f;
    h.ratio = float(ratio);
    h.step = float(step_mm * scale / h.scaling);
    return h;
}

// Covering radius and neighbourhood reaches of a table, by brute force (cached per ratio).
struct TableAngles {
    double covering, reach1, reach2, reach3;
};
const TableAngles& table_angles(float ratio) {
    static std::map<float, TableAngles> cache;
    auto it = cache.find(ratio);
    if (it == cache.end()) {
        const DirectionTable t(ratio);
        it = cache.emplace(ratio, TableAngles{test::covering_radius(t), test::neighbourhood_reach(t, 1),
                                              test::neighbourhood_reach(t, 2), test::neighbourhood_reach(t, 3)})
                 .first;
    }
    return it->second;
}

// The bound's parameters for an 8-bit encoding (formats/error-bound.md, "The parameters").
test::BoundParams bound_params(const FftHeader& h, const SearchOptions& s, double max_abs_coordinate) {
    const TableAngles& a = table_angles(h.ratio);
    test::BoundParams p;
    p.step = double(h.step) * h.scaling;
    p.cap_angle = std::acos(std::clamp(1.0 - double(h.ratio), -1.0, 1.0));
    // The code chooser: the lookup (cells of half-diagonal sqrt(2) tan(cap) / G
    // in gnomonic units, counted twice) when the cap is narrower than a half
    // sphere, else nearest_code (the formula code refined over its 3x3
    // neighbourhood: within one neighbour step of the covering radius).
    const double chooser = h.ratio < 1.0f ? a.covering + 2 * std::sqrt(2.0) * std::tan(p.cap_angle) /
                                                             detail::NearestCodeLut::kGrid
                                          : a.covering + a.reach1;
    // The lookahead (greedy aiming, beam 1) may take any code of the aimed one's 3x3.
    const unsigned lookahead_radius = s.beam_width <= 1 && s.lookahead > 0 ? 1u : 0u;
    const unsigned r = std::max({s.beam_width > 1 ? s.radius : 0u, s.retry_beam_width > 1 ? s.retry_radius : 0u,
                                 lookahead_radius});
    p.aim_angle = chooser + (r == 1 ? a.reach1 : r == 2 ? a.reach2 : r == 3 ? a.reach3 : 0.0) + 1e-5;
    const double ulp = std::ldexp(1.0, -24);
    // A full quantum, not half: where a block's first segment runs along the
    // helper vector the encoder may round an anchor the other way to
    // condition the first frame (encode/anchor_conditioning.hpp).
    p.anchor_error = std::sqrt(3.0) * (1.0 / 65535 + ulp) * h.scaling;
    p.step_slack = 4 * ulp * h.scaling;
    p.point_slack = 4 * ulp * (h.scaling + max_abs_coordinate);
    return p;
}

double max_abs(const std::vector<Fiber>& fibers) {
    double m = 0;
    for (const Fiber& f : fibers)
        for (const Vec3f& p : f) m = std::max({m, double(std::fabs(p.x)), double(std::fabs(p.y)), double(std::fabs(p.z))});
    return m;
}

struct Outcome {
    double max_error = 0, max_excess = -INFINITY;  // excess: error - bound
};

// Encodes every fiber with every search, decodes with the scalar decoder and
// checks each point against its bound.
void check_encoding_into(const std::vector<Fiber>& fibers, const FftHeader& h, const char* label, Outcome& o) {
    const DecodeContext ctx(h);
    const double coord = max_abs(fibers);
    for (const auto& [name, search] : searches()) {
        const FiberEncoder encoder(h, search);
        const test::BoundParams bp = bound_params(h, search, coord);
        for (std::size_t i = 0; i < fibers.size(); ++i) {
            const Fiber& f = fibers[i];
            std::vector<std::uint8_t> blocks;
            std::vector<Vec3f> predicted;
            encoder.encode(f, std::uint32_t(i), blocks, &predicted);
            const std::size_t count = blocks.size() / h.block_bytes();
            ASSERT_EQ(count, encoder.block_count(f.size()));
            ASSERT_EQ(count_block_points(ctx, blocks.data(), count), f.size());
            std::vector<float> xyz(3 * f.size());
            ASSERT_EQ(decode_blocks_scalar(ctx, blocks.data(), count, xyz.data()), f.size());
            const std::vector<double> bound = test::error_bounds(f, h.points_per_block, bp);
            for (std::size_t k = 0; k < f.size(); ++k) {
                const Vec3f d{xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]};
                ASSERT_TRUE(std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z))
                    << label << " " << name << " fiber " << i << " point " << k;
                ASSERT_EQ(d, predicted[k]) << "the encoder's closed loop disagrees with the decoder";
                const double e = std::sqrt(std::pow(double(d.x) - f[k].x, 2) + std::pow(double(d.y) - f[k].y, 2) +
                                           std::pow(double(d.z) - f[k].z, 2));
                o.max_error = std::max(o.max_error, e);
                o.max_excess = std::max(o.max_excess, e - bound[k]);
                ASSERT_LE(e, bound[k]) << label << " " << name << " fiber " << i << " point " << k << " of "
                                       << f.size();
            }
        }
    }
}

Outcome check_encoding(const std::vector<Fiber>& fibers, const FftHeader& h, const char* label) {
    Outcome o;
    check_encoding_into(fibers, h, label, o);
    return o;
}

// Fibers walking a fixed step with turns of at most `max_turn` radians per
// step, each turn about a random axis (like probabilistic tractography).
std::vector<Fiber> random_walks(int count, int points, double step, double max_turn, unsigned seed,
                                Vec3f origin = {0, 0, 0}) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<Fiber> out;
    for (int i = 0; i < count; ++i) {
        double p[3] = {origin.x + 5 * u(rng), origin.y + 5 * u(rng), origin.z + 5 * u(rng)};
        double d[3] = {u(rng), u(rng), u(rng)};
        Fiber f;
        for (int k = 0; k < points; ++k) {
            f.push_back({float(p[0]), float(p[1]), float(p[2])});
            // Turn d by an angle in [0, max_turn] towards a random perpendicular.
            const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (double& c : d) c /= n;
            double r[3] = {u(rng), u(rng), u(rng)};
            const double rd = r[0] * d[0] + r[1] * d[1] + r[2] * d[2];
            for (int a = 0; a < 3; ++a) r[a] -= rd * d[a];
            const double rn = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
            const double t = max_turn * std::fabs(u(rng));
            for (int a = 0; a < 3; ++a) d[a] = std::cos(t) * d[a] + std::sin(t) * r[a] / rn;
            for (int a = 0; a < 3; ++a) p[a] += step * d[a];
        }
        out.push_back(std::move(f));
    }
    return out;
}

Fiber straight_line(Vec3f from, Vec3f dir, double step, int points) {
    const double n = std::sqrt(double(dir.x) * dir.x + double(dir.y) * dir.y + double(dir.z) * dir.z);
    Fiber f;
    for (int k = 0; k < points; ++k)
        f.push_back({float(from.x + k * step * dir.x / n), float(from.y + k * step * dir.y / n),
                     float(from.z + k * step * dir.z / n)});
    return f;
}

constexpr double kDeg = M_PI / 180;
double ratio_for_angle(double a) { return 1 - std::cos(a); }

}  // namespace

TEST(EncodeStress, FiberOf100000Points) {
    // 10 m of fiber wound into a 30 x 30 x 50 mm helix with wiggles (turns
    // of up to ~7 degrees per step, inside the 12-degree cap), so that anchors
    // stay fine-grained and the bound is set by the codes. Resampled to an
    // exact 0.1 mm step.
    Fiber raw;
    for (int k = 0; k < 400000; ++k) {
        const double t = 0.025 * k / 15.0;  // ~0.025 mm of arc per raw point
        raw.push_back({float(15 * std::cos(t) + 0.1 * std::sin(37 * t)), float(15 * std::sin(t) + 0.1 * std::cos(29 * t)),
                       float(0.08 * t + 0.2 * std::sin(23 * t))});
    }
    Fiber f;
    resample_fixed_step(raw, 0.1, f);
    f.resize(100000);
    ASSERT_EQ(f.size(), 100000u);
    const FftHeader h = header_for({f}, 8, ratio_for_angle(12 * kDeg), 0.1, 1.0005);
    const Outcome o = check_encoding({f}, h, "1e5 points");
    EXPECT_GT(o.max_excess, -1e-3);  // somewhere the bound is within 1 um of the error: not vacuous
}

TEST(EncodeStress, SharpTurnsAtAndBeyondTheCap) {
    // Straight runs of 7 steps joined by turns of exactly the cap angle, and
    // of 1.5 and 3 times it, in varying planes.
    const double cap = 18 * kDeg;
    for (double factor : {1.0, 1.5, 3.0}) {
        Fiber f;
        double p[3] = {0, 0, 0}, d[3] = {1, 0, 0};
        for (int k = 0; k < 400; ++k) {
            f.push_back({float(p[0]), float(p[1]), float(p[2])});
            if (k % 7 == 6) {
                // Turn d by factor * cap towards a perpendicular that varies with k.
                double w[3] = {std::sin(k), std::cos(k), 0.5};
                const double wd = w[0] * d[0] + w[1] * d[1] + w[2] * d[2];
                double a[3] = {w[0] - wd * d[0], w[1] - wd * d[1], w[2] - wd * d[2]};
                const double an = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
                const double t = factor * cap;
                for (int i = 0; i < 3; ++i) d[i] = std::cos(t) * d[i] + std::sin(t) * a[i] / an;
            }
            for (int i = 0; i < 3; ++i) p[i] += 0.1 * d[i];
        }
        const FftHeader h = header_for({f}, 8, ratio_for_angle(cap), 0.1);
        check_encoding({f}, h, factor == 1.0 ? "turns at the cap" : "turns beyond the cap");
    }
}

TEST(EncodeStress, StepJitterOf15Percent) {
    // Encoded as they are: the decoder walks one step, so the bound grows with
    // the spacing mismatch, but it holds and nothing breaks.
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> jitter(0.85, 1.15);
    auto fibers = random_walks(20, 300, 0.1, 10 * kDeg, 4);
    for (Fiber& f : fibers) {  // each segment stretched by its own factor
        Fiber g{f[0]};
        for (std::size_t k = 1; k < f.size(); ++k) {
            const double s = jitter(rng);
            g.push_back({float(g.back().x + s * (f[k].x - f[k - 1].x)), float(g.back().y + s * (f[k].y - f[k - 1].y)),
                         float(g.back().z + s * (f[k].z - f[k - 1].z))});
        }
        f = g;
    }
    check_encoding(fibers, header_for(fibers, 8, ratio_for_angle(25 * kDeg), 0.1), "jitter");

    // Through the pipeline: the jittered input is resampled to the fixed step
    // (a point per step on the cubic through its points), and the decoded
    // points stay within the bound of the resampled points.
    test::TempDir dir;
    {
        TckWriter w(dir.file("jitter.tck"), {}, false);
        for (const Fiber& f : fibers) w.write(f);
        w.finish();
    }
    CompressOptions o;
    o.search = search_for_effort(2);
    const CompressReport r = compress_file(dir.file("jitter.tck"), dir.file("jitter.fft"), o);
    ASSERT_TRUE(r.resampled);
    const FftFile file(dir.file("jitter.fft"));
    const Streamlines s = decode_fibers(file, 0, file.header().fibers);
    const double coord = max_abs(fibers);
    for (std::size_t i = 0; i < fibers.size(); ++i) {
        std::vector<Vec3f> resampled;
        resample_keeping_end(fibers[i], *file.resampling(), resampled);
        ASSERT_EQ(resampled.size(), s.offsets[i + 1] - s.offsets[i]);
        const auto bound = test::error_bounds(resampled, r.header.points_per_block, bound_params(r.header, r.search, coord));
        for (std::size_t k = 0; k < resampled.size(); ++k) {
            const float* p = &s.xyz[3 * (s.offsets[i] + k)];
            ASSERT_TRUE(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]));
            const double e = std::hypot(double(p[0]) - resampled[k].x, double(p[1]) - resampled[k].y,
                                        double(p[2]) - resampled[k].z);
            ASSERT_LE(e, bound[k] + 1e-6) << "fiber " << i << " point " << k;
        }
    }
}

TEST(EncodeStress, CoordinatesNearZeroAndUpTo1e4Millimetres) {
    // A fiber crossing the origin; a tiny one (0.02 mm long, 0.1 um steps).
    check_encoding({straight_line({-1, -1, -1}, {1, 1, 1}, 0.1, 40), straight_line({0, 0, 0}, {0, 1, 0.2f}, 1e-4, 200)},
                   header_for({straight_line({-1, -1, -1}, {1, 1, 1}, 0.1, 40)}, 8, ratio_for_angle(15 * kDeg), 0.1),
                   "through the origin");
    const Fiber tiny = straight_line({1e-6f, 0, 0}, {0, 1, 0.2f}, 1e-4, 200);
    check_encoding({tiny}, header_for({tiny}, 8, ratio_for_angle(15 * kDeg), 1e-4), "tiny");
    // Far from the origin: float32 input itself is only ~1 um precise there.
    const auto far = random_walks(3, 200, 0.1, 10 * kDeg, 5, {1e4f, 1e4f, 1e4f});
    const Outcome o = check_encoding(far, header_for(far, 8, ratio_for_angle(20 * kDeg), 0.1), "at 1e4 mm");
    EXPECT_LT(o.max_error, 0.05);
    // Spanning 0 .. 1e4 mm: the unorm16 anchors are 0.15 mm apart, more than
    // a step; the cap must be the whole sphere (compute_ratio gives 2).
    std::vector<Fiber> span = random_walks(2, 200, 0.1, 10 * kDeg, 6);
    span.push_back(straight_line({1e4f, 1e4f, 1e4f}, {1, 0, 0}, 0.1, 100));
    const FftHeader wide = header_for(span, 8, 2.0, 0.1);
    EXPECT_EQ(compute_ratio(wide.scaling, 0.1, 1.0), 2.0f);
    check_encoding(span, wide, "0 to 1e4 mm");
}

TEST(EncodeStress, DirectionsParallelToTheFrameHelper) {
    // Along +C and -C; with 10 mm steps the anchors' axis is within 0.06
    // degree of C, where frame_from_axis switches to its second helper.
    const Vec3f c{kFrameHelper[0], kFrameHelper[1], kFrameHelper[2]};
    const Vec3f minus_c{-c.x, -c.y, -c.z};
    for (double step : {0.1, 10.0}) {
        const std::vector<Fiber> fibers = {straight_line({0, 0, 0}, c, step, 130), straight_line({5, 5, 5}, minus_c, step, 130)};
        check_encoding(fibers, header_for(fibers, 8, ratio_for_angle(10 * kDeg), step), "along C");
    }
}

TEST(EncodeStress, StraightLines) {
    std::vector<Fiber> fibers;
    for (Vec3f dir : {Vec3f{1, 0, 0}, Vec3f{0, 1, 0}, Vec3f{0, 0, -1}, Vec3f{1, 2, 3}, Vec3f{-0.3f, 0.9f, 0.1f}})
        fibers.push_back(straight_line({1, 2, 3}, dir, 0.1, 250));
    for (double scale : {1.0, 1.0005})
        for (double ratio : {0.01, 0.05, 0.146}) {
            const Outcome o = check_encoding(fibers, header_for(fibers, 8, ratio, 0.1, scale), "straight");
            EXPECT_LT(o.max_error, 0.02);
        }
}

TEST(EncodeStress, TinyLoops) {
    // Circles of 3 to 6 steps per turn (60 to 120 degrees per step) and a
    // helix, far sharper than any cap but the whole sphere.
    std::vector<Fiber> fibers;
    for (int per_turn : {3, 4, 6}) {
        Fiber f;
        const double r = 0.1 / (2 * std::sin(M_PI / per_turn));
        for (int k = 0; k < 150; ++k) {
            const double a = 2 * M_PI * k / per_turn;
            f.push_back({float(r * std::cos(a)), float(r * std::sin(a)), float(0.001 * k * (per_turn == 6))});
        }
        fibers.push_back(f);
    }
    for (double ratio : {ratio_for_angle(30 * kDeg), 1.0, 2.0})
        check_encoding(fibers, header_for(fibers, 8, ratio, 0.1), "tiny loops");
}

TEST(EncodeStress, OneAndTwoPointFibers) {
    const std::vector<Fiber> fibers = {{{1, 2, 3}}, {{1, 2, 3}, {1.1f, 2, 3}}, {{-4, 0, 7}}, {{0, 0, 0}, {0, 0, 0}}};
    const FftHeader h = header_for(fibers, 8, 0.1, 0.1);
    check_encoding(fibers, h, "short fibers");
    // A fiber of 61 points: its second block holds one point, whose second
    // anchor is the extrapolated tangent.
    const std::vector<Fiber> f61 = {straight_line({0, 0, 0}, {1, 1, 0}, 0.1, 61)};
    check_encoding(f61, header_for(f61, 8, 0.1, 0.1), "61 points");
}

TEST(EncodeStress, Float64Input) {
    // A Float64LE .tck (written by hand: TckWriter writes float32) whose
    // coordinates are not float-representable; the pipeline reads them as
    // float, so the error against the doubles is the bound plus that rounding.
    test::TempDir dir;
    const auto walks = random_walks(5, 180, 0.1, 10 * kDeg, 9);
    std::vector<std::vector<std::array<double, 3>>> exact;
    for (const Fiber& f : walks) {
        std::vector<std::array<double, 3>> e;
        for (const Vec3f& p : f) e.push_back({p.x + 1e-9, p.y - 2e-9, p.z + 3e-9});
        exact.push_back(e);
    }
    std::string header = "mrtrix tracks\ncount: " + std::to_string(exact.size()) + "\ndatatype: Float64LE\nfile: . ";
    const std::size_t offset = 128;
    header += std::to_string(offset) + "\nEND\n";
    header.resize(offset, '\0');
    std::string data = header;
    auto put = [&](double x, double y, double z) {
        const double v[3] = {x, y, z};
        data.append(reinterpret_cast<const char*>(v), sizeof v);
    };
    for (const auto& e : exact) {
        for (const auto& p : e) put(p[0], p[1], p[2]);
        put(NAN, NAN, NAN);
    }
    put(INFINITY, INFINITY, INFINITY);
    test::write_file(dir.file("f64.tck"), data);

    CompressOptions o;
    const CompressReport r = compress_file(dir.file("f64.tck"), dir.file("f64.fft"), o);
    ASSERT_FALSE(r.resampled);
    const FftFile file(dir.file("f64.fft"));
    const Streamlines s = decode_fibers(file, 0, file.header().fibers);
    for (std::size_t i = 0; i < exact.size(); ++i) {
        Fiber as_read;
        for (const auto& p : exact[i]) as_read.push_back({float(p[0]), float(p[1]), float(p[2])});
        const auto bound = test::error_bounds(as_read, r.header.points_per_block,
                                              bound_params(r.header, r.search, max_abs({as_read})));
        for (std::size_t k = 0; k < exact[i].size(); ++k) {
            const float* p = &s.xyz[3 * (s.offsets[i] + k)];
            ASSERT_TRUE(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]));
            const double e = std::sqrt(std::pow(p[0] - exact[i][k][0], 2) + std::pow(p[1] - exact[i][k][1], 2) +
                                       std::pow(p[2] - exact[i][k][2], 2));
            const double rounding = std::sqrt(3.0) * std::ldexp(1.0, -24) * 16;  // float vs double at |x| < 16 mm
            ASSERT_LE(e, bound[k] + rounding) << "fiber " << i << " point " << k;
        }
    }
}

TEST(EncodeStress, SixteenBitCodesStayWithinTheEightBitBoundAndFarBelowIt) {
    // The 16-bit levels include the 8-bit ones (255 = 15 x 17), so its
    // covering radius is smaller, and its chooser's slack (one 16-bit
    // neighbour, 1/17 of an 8-bit step) is below the 8-bit lookup's; its
    // anchors are unorm24: the 8-bit bound holds for it too.
    const auto fibers = random_walks(4, 500, 0.1, 12 * kDeg, 11);
    const FftHeader h16 = header_for(fibers, 16, ratio_for_angle(20 * kDeg), 0.1);
    FftHeader h8 = h16;
    h8.version = kFftVersion;
    h8.points_per_block = kDefaultPointsPerBlock;
    const DecodeContext ctx(h16);
    const FiberEncoder encoder(h16, {1, 1, 0, 1, 0});
    double max16 = 0;
    for (const Fiber& f : fibers) {
        std::vector<std::uint8_t> blocks;
        std::vector<Vec3f> predicted;
        encoder.encode(f, 0, blocks, &predicted);
        std::vector<float> xyz(3 * f.size());
        decode_blocks_scalar16(ctx, blocks.data(), blocks.size() / h16.block_bytes(), xyz.data());
        // The 8-bit bound for 126-point blocks (a longer walk than 60).
        const auto bound = test::error_bounds(f, h16.points_per_block, bound_params(h8, {1, 1, 0, 1, 0}, 20));
        for (std::size_t k = 0; k < f.size(); ++k) {
            const Vec3f d{xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]};
            ASSERT_EQ(d, predicted[k]);
            const double e = std::sqrt(std::pow(double(d.x) - f[k].x, 2) + std::pow(double(d.y) - f[k].y, 2) +
                                       std::pow(double(d.z) - f[k].z, 2));
            ASSERT_LE(e, bound[k]);
            max16 = std::max(max16, e);
        }
    }
    EXPECT_LT(max16, 1e-3);  // under a micrometre
}
