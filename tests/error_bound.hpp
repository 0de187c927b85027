// The a-priori bound on the encoder's point errors derived in
// formats/error-bound.md, evaluated along a fiber: tests assert that every
// decoded point lies within it. It depends only on the input polyline and on
// four numbers of the encoding (decoder step, the angle between an aim and
// the code the search may choose, the cap angle, the anchor quantization),
// never on the codes the encoder picked.
#pragma once

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "fiblet/direction_code.hpp"
#include "fiblet/geometry.hpp"

namespace fiblet::test {

struct BoundParams {
    double step = 0;          // decoder step delta' (mm)
    double aim_angle = 0;     // gamma: largest angle between an aim inside the cap and a code the search may choose
    double cap_angle = 0;     // Theta_c = acos(1 - ratio)
    double anchor_error = 0;  // eps_a: largest distance between an anchor and its input point (mm)
    double step_slack = 0;    // eta: float rounding per decoder step (mm)
    double point_slack = 0;   // float rounding of an output point (mm)
};

namespace bound_detail {
struct V {
    double x, y, z;
};
inline V sub(Vec3f a, Vec3f b) { return {double(a.x) - b.x, double(a.y) - b.y, double(a.z) - b.z}; }
inline double norm(V a) { return std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z); }
inline double angle(V a, V b) {
    const double na = norm(a), nb = norm(b);
    if (!(na > 0 && nb > 0)) return M_PI;
    // atan2(|a x b|, a.b): accurate for tiny and for near-pi angles.
    const V c{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    return std::atan2(norm(c), a.x * b.x + a.y * b.y + a.z * b.z);
}
}  // namespace bound_detail

// Bound on |decoded_k - input_k| for every point of a fiber encoded in blocks
// of `points_per_block` points (formats/error-bound.md, "The recursion").
inline std::vector<double> error_bounds(std::span<const Vec3f> f, std::uint32_t points_per_block, const BoundParams& p) {
    using namespace bound_detail;
    std::vector<double> out(f.size());
    const double d1 = p.step;
    for (std::size_t i0 = 0; i0 < f.size(); i0 += points_per_block) {
        const std::size_t n = std::min<std::size_t>(points_per_block, f.size() - i0);
        out[i0] = p.anchor_error + p.point_slack;
        if (n < 2) continue;
        out[i0 + 1] = p.anchor_error + p.point_slack;
        // State after point 1: along/lateral error bounds relative to the last
        // input segment, and the decoded heading's angle to that segment.
        double L = p.anchor_error, P = p.anchor_error;
        const V seg0 = sub(f[i0 + 1], f[i0]);
        const double d0 = norm(seg0);
        double H = 2 * p.anchor_error < d0 ? std::asin(2 * p.anchor_error / d0) : M_PI;
        V prev = seg0;
        for (std::size_t k = 1; k + 1 < n; ++k) {
            const V seg = sub(f[i0 + k + 1], f[i0 + k]);
            const double dk = norm(seg);
            const double theta = angle(prev, seg);
            // 1. Components relative to the next segment.
            const double Lp = L + P * std::sin(std::min(theta, M_PI / 2)) + (theta > M_PI / 2 ? P : 0.0);
            const double Pp = P + L * std::sin(std::min(theta, M_PI / 2)) + (theta > M_PI / 2 ? L : 0.0);
            double Lnext, Pnext, Hnext;
            bool trivial = !(dk > 0) || !(Lp < 0.5 * dk) || !(prev.x * prev.x + prev.y * prev.y + prev.z * prev.z > 0);
            if (!trivial) {
                // 2. The aim v = t_{k+1} - p_k and its angle beta to the segment.
                const double beta = std::atan(Pp / (dk - Lp));
                // 3-4. Aim angle from the decoded axis; angle from the aim to the code.
                const double phi = H + theta + beta;
                const double alpha = p.aim_angle + std::max(0.0, phi - p.cap_angle);
                if (alpha < M_PI / 2) {
                    // 5. Radial and lateral parts of the new error.
                    const double X = Pp * Pp / (2 * (dk - Lp));
                    const double R = Lp + std::max(std::fabs(d1 - dk), std::fabs(d1 * std::cos(alpha) - dk) + X);
                    const double S = d1 * std::sin(alpha);
                    // 6-7. Relative to the segment just walked; heading.
                    Lnext = R + S * std::sin(beta);
                    Pnext = R * std::sin(beta) + S;
                    Hnext = alpha + beta;
                } else {
                    trivial = true;
                }
            }
            if (trivial) {  // |e_{k+1}| <= |e_k| + delta' + delta_k, any direction
                const double e = std::hypot(L, P) + d1 + dk;
                Lnext = Pnext = e;
                Hnext = M_PI;
            }
            L = Lnext + p.step_slack, P = Pnext + p.step_slack, H = std::min(Hnext, M_PI);
            out[i0 + k + 1] = std::hypot(L, P) + p.point_slack;
            if (dk > 0) prev = seg;
        }
    }
    return out;
}

// Covering radius of a direction table inside its cap: the largest angle
// from a direction of the cap to the nearest of the 256 codes, by brute
// force over a grid of directions, plus the grid's own spacing (the angle
// to the nearest code is 1-Lipschitz).
inline double covering_radius(const DirectionTable& t, int grid = 160) {
    const double cap = std::acos(std::clamp(1.0 - double(t.ratio()), -1.0, 1.0));
    double worst = 0;
    const double dphi = 2 * M_PI / (4 * grid), dpolar = cap / grid;
    for (int i = 0; i <= grid; ++i) {
        const double polar = cap * i / grid;
        for (int j = 0; j < 4 * grid; ++j) {
            const double az = dphi * j;
            const Vec3f d{float(std::cos(polar)), float(std::sin(polar) * std::cos(az)), float(std::sin(polar) * std::sin(az))};
            double best = -2;
            for (int c = 0; c < 256; ++c) {
                const Vec3f& e = t.direction(std::uint8_t(c));
                best = std::max(best, double(e.x) * d.x + double(e.y) * d.y + double(e.z) * d.z);
            }
            worst = std::max(worst, std::acos(std::min(best, 1.0)));
        }
    }
    // Largest distance from any direction to the nearest grid direction.
    const double spacing = std::hypot(dpolar, std::sin(cap) * dphi) / 2;
    return worst + spacing;
}

// Largest angle between a code and the codes within `radius` levels of it
// on both axes (what a beam adds to the aim error).
inline double neighbourhood_reach(const DirectionTable& t, int radius) {
    double worst = 0;
    for (int h = 0; h < 16; ++h)
        for (int l = 0; l < 16; ++l)
            for (int dh = -radius; dh <= radius; ++dh)
                for (int dl = -radius; dl <= radius; ++dl) {
                    if (h + dh < 0 || h + dh > 15 || l + dl < 0 || l + dl > 15) continue;
                    const Vec3f& a = t.direction(std::uint8_t(h << 4 | l));
                    const Vec3f& b = t.direction(std::uint8_t((h + dh) << 4 | (l + dl)));
                    const double c = double(a.x) * b.x + double(a.y) * b.y + double(a.z) * b.z;
                    worst = std::max(worst, std::acos(std::clamp(c, -1.0, 1.0)));
                }
    return worst;
}

}  // namespace fiblet::test
