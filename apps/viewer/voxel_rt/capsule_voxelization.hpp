// Conservative voxelization of a capsule (a segment swept by a ball of
// radius r), the CPU twin of capsule_voxels.glsl: the same float operations
// in the same order, so that both visit the same voxels.
//
// Everything is in voxel units (voxel v covers [v, v + 1) on each axis).
// The segment a -> b, unit direction u, is marched along its major axis a0
// (|u_a0| largest) one slab [i, i + 1) at a time; per slab the visited box
// of the minor axes a1, a2 covers the capsule's cross-sections there.
//
// Why the box is exact enough: the capsule lies inside the infinite
// cylinder of radius r around its axis (its end balls are centred on the
// axis), so its cross-section by a plane x_a0 = x lies inside the ellipse
// the plane cuts from that cylinder. For an offset q = (0, y1, y2) from the
// axis point in that plane, q is inside when |q|² − (q·u)² ≤ r², i.e.
//   y1²(1 − u1²) + y2²(1 − u2²) − 2 y1 y2 u1 u2 ≤ r².
// Maximising y1 under this quadratic form gives y1² ≤ r² / (A − B²/C) with
// A = 1 − u1², B = u1 u2, C = 1 − u2², and A − B²/C = u0² / (1 − u2²), so
// the ellipse's half-extent along a1 is
//   e1 = r · sqrt(1 − u2²) / |u0|      (and e2 = r · sqrt(1 − u1²) / |u0|).
// The axis point moves linearly with x, so per slab the box spans the axis
// points at the slab's two ends (clamped to the capsule's extent along a0,
// [min − r, max + r], the axis extrapolated beyond the segment) widened by e1, e2, and is intersected with the
// capsule's bounding box. Widening by r alone (the paper's Eq. (1) as
// reconstructed here, see HalfExtentRule::radius_only) misses voxels of
// oblique capsules: kept as the negative check of the tests.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace fiblet::viewer::voxel_rt {

enum class HalfExtentRule {
    ellipse,      // r sqrt(1 − u_a2²) / |u_a0| (exact; what the viewer uses)
    radius_only,  // r (not conservative: the negative check)
};

// Calls visit(x, y, z) for every voxel of the n³ grid the capsule may
// touch (a superset of the voxels it touches; each voxel at most once).
template <class Visit>
void for_each_capsule_voxel(const std::array<float, 3>& a, const std::array<float, 3>& b, float r, int n,
                            Visit&& visit, HalfExtentRule rule = HalfExtentRule::ellipse) {
    const float d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const float len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    // Major axis a0 and the two minor axes a1, a2 (a point is a ball: any axis).
    int a0 = 0;
    if (std::fabs(d[1]) > std::fabs(d[a0])) a0 = 1;
    if (std::fabs(d[2]) > std::fabs(d[a0])) a0 = 2;
    const int a1 = (a0 + 1) % 3, a2 = (a0 + 2) % 3;
    float u0 = 1, u1 = 0, u2 = 0;
    if (len > 0) u0 = d[a0] / len, u1 = d[a1] / len, u2 = d[a2] / len;
    float e1 = r, e2 = r;
    if (rule == HalfExtentRule::ellipse) {
        e1 = r * std::sqrt(std::max(1.0f - u2 * u2, 0.0f)) / std::fabs(u0);
        e2 = r * std::sqrt(std::max(1.0f - u1 * u1, 0.0f)) / std::fabs(u0);
    }
    // The capsule's extent along each axis.
    float lo[3], hi[3];
    for (int k = 0; k < 3; ++k) lo[k] = std::min(a[k], b[k]) - r, hi[k] = std::max(a[k], b[k]) + r;
    // Axis point at x along a0 (slope along the minor axes per unit of a0).
    const float s1 = d[a0] != 0 ? d[a1] / d[a0] : 0.0f, s2 = d[a0] != 0 ? d[a2] / d[a0] : 0.0f;
    const int i_lo = std::max(int(std::floor(lo[a0])), 0), i_hi = std::min(int(std::floor(hi[a0])), n - 1);
    for (int i = i_lo; i <= i_hi; ++i) {
        // The slab's part of the capsule's extent along a0; the axis is
        // extrapolated there (beyond the ends, the cylinder's cross-sections
        // lean past the end points).
        const float x0 = std::clamp(float(i), lo[a0], hi[a0]), x1 = std::clamp(float(i + 1), lo[a0], hi[a0]);
        const float c1a = a[a1] + (x0 - a[a0]) * s1, c1b = a[a1] + (x1 - a[a0]) * s1;
        const float c2a = a[a2] + (x0 - a[a0]) * s2, c2b = a[a2] + (x1 - a[a0]) * s2;
        const float l1 = std::max(std::min(c1a, c1b) - e1, lo[a1]), h1 = std::min(std::max(c1a, c1b) + e1, hi[a1]);
        const float l2 = std::max(std::min(c2a, c2b) - e2, lo[a2]), h2 = std::min(std::max(c2a, c2b) + e2, hi[a2]);
        const int j_lo = std::max(int(std::floor(l1)), 0), j_hi = std::min(int(std::floor(h1)), n - 1);
        const int k_lo = std::max(int(std::floor(l2)), 0), k_hi = std::min(int(std::floor(h2)), n - 1);
        for (int j = j_lo; j <= j_hi; ++j)
            for (int k = k_lo; k <= k_hi; ++k) {
                int v[3];
                v[a0] = i, v[a1] = j, v[a2] = k;
                visit(v[0], v[1], v[2]);
            }
    }
}

}  // namespace fiblet::viewer::voxel_rt
