// Real spherical harmonics of even degree, as MRtrix3 3.0 stores FOD images
// (its default `tournier` convention): coefficient l(l+1)/2 + m for
// l = 0, 2, ..., lmax and m = -l..l;
//   m = 0:  N_l P_l(cos θ)
//   m > 0:  √2 N_lm P_l^m(cos θ) cos(mφ)
//   m < 0:  √2 N_l|m| P_l^|m|(cos θ) sin(|m|φ)
// with orthonormal N and P_l^m carrying the Condon–Shortley phase (−1)^m,
// as MRtrix3's Legendre functions and scipy's lpmv do (sh2amp agrees; the
// shared phantom script's docstring says otherwise, its code has the phase). One recurrence, written
// twice: here (templated, double for the CPU references) and in
// sh_basis.glsl (the glyph shaders), so that tests can compare the two; the
// same for its derivative (sh_value_and_gradient, the glyphs' normals).
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "fiblet_viewer/scene_sources.hpp"

namespace fiblet::viewer {

inline constexpr int sh_coefficient_count(int lmax) { return (lmax + 1) * (lmax + 2) / 2; }
inline constexpr int sh_index(int l, int m) { return l * (l + 1) / 2 + m; }
// The lmax of an image with `count` coefficients, or -1 when no even lmax <= 12 has that many.
int sh_lmax_for_count(long count);

// Σ c_i Y_i(u) for a unit direction u, coefficients `c` up to `lmax`.
// Associated Legendre functions by the normalised three-term recurrence with
// sin^m θ · e^{imφ} carried as (x + iy)^m, so that no trigonometry is needed.
template <class T, class Coefficients>
T sh_value(const Coefficients& c, int lmax, T x, T y, T z) {
    const T sqrt2 = std::sqrt(T(2));
    T pmm = T(0.28209479177387814347);  // N_00 = 1 / sqrt(4π)
    T re = 1, im = 0;                   // (x + iy)^m
    T sum = 0;
    for (int m = 0; m <= lmax; ++m) {
        if (m > 0) {
            pmm *= -std::sqrt(T(2 * m + 1) / T(2 * m));  // − : the Condon–Shortley phase
            const T r = re * x - im * y;
            im = re * y + im * x, re = r;
        }
        T p2 = 0, p1 = 0;  // the values at l - 2 and l - 1
        for (int l = m; l <= lmax; ++l) {
            T p;
            if (l == m) p = pmm;
            else if (l == m + 1) p = std::sqrt(T(2 * m + 3)) * z * pmm;
            else {
                const T ll = T(l), mm = T(m);
                const T a = std::sqrt((4 * ll * ll - 1) / (ll * ll - mm * mm));
                const T b = std::sqrt(((ll - 1) * (ll - 1) - mm * mm) / (4 * (ll - 1) * (ll - 1) - 1));
                p = a * (z * p1 - b * p2);
            }
            p2 = p1, p1 = p;
            if (l % 2) continue;
            if (m == 0) sum += T(c[sh_index(l, 0)]) * p;
            else sum += sqrt2 * p * (re * T(c[sh_index(l, m)]) + im * T(c[sh_index(l, -m)]));
        }
    }
    return sum;
}

// f(u) and its gradient on the sphere, ∇_S f(u) (tangent at u): the same
// recurrence differentiated. On the sphere f equals the polynomial
// E(x) = Σ c_lm q_lm(z) Re/Im (x + iy)^m, q_lm the recurrence's values as
// a polynomial in z (P_l^m(z) without its sin^m θ, which (x + iy)^m
// carries); so ∇_S f is ∇E less its radial part, with
//   ∂/∂z:  q'_lm(z) (x + iy)^m,  q'_l = a (q_{l−1} + z q'_{l−1} − b q'_{l−2}),
//   ∂/∂x, ∂/∂y:  q_lm(z) m (x + iy)^{m−1} times 1 and i.
template <class T, class Coefficients>
T sh_value_and_gradient(const Coefficients& c, int lmax, T x, T y, T z, T (&gradient)[3]) {
    const T sqrt2 = std::sqrt(T(2));
    T pmm = T(0.28209479177387814347);
    T re = 1, im = 0;  // (x + iy)^m
    T sum = 0, gx = 0, gy = 0, gz = 0;
    for (int m = 0; m <= lmax; ++m) {
        const T re1 = re, im1 = im;  // (x + iy)^{m−1} once m > 0
        if (m > 0) {
            pmm *= -std::sqrt(T(2 * m + 1) / T(2 * m));
            const T r = re * x - im * y;
            im = re * y + im * x, re = r;
        }
        T p2 = 0, p1 = 0, d2 = 0, d1 = 0;  // q and q' at l − 2 and l − 1
        for (int l = m; l <= lmax; ++l) {
            T p, d;
            if (l == m) p = pmm, d = 0;
            else if (l == m + 1) {
                const T s = std::sqrt(T(2 * m + 3));
                p = s * z * pmm, d = s * pmm;
            } else {
                const T ll = T(l), mm = T(m);
                const T a = std::sqrt((4 * ll * ll - 1) / (ll * ll - mm * mm));
                const T b = std::sqrt(((ll - 1) * (ll - 1) - mm * mm) / (4 * (ll - 1) * (ll - 1) - 1));
                p = a * (z * p1 - b * p2);
                d = a * (p1 + z * d1 - b * d2);
            }
            p2 = p1, p1 = p, d2 = d1, d1 = d;
            if (l % 2) continue;
            if (m == 0) {
                const T cl = T(c[sh_index(l, 0)]);
                sum += cl * p, gz += cl * d;
            } else {
                const T cp = T(c[sh_index(l, m)]), cm = T(c[sh_index(l, -m)]);
                const T w = sqrt2 * (re * cp + im * cm), pm = sqrt2 * T(m) * p;
                sum += p * w, gz += d * w;
                gx += pm * (re1 * cp + im1 * cm);
                gy += pm * (re1 * cm - im1 * cp);
            }
        }
    }
    const T radial = gx * x + gy * y + gz * z;
    gradient[0] = gx - radial * x, gradient[1] = gy - radial * y, gradient[2] = gz - radial * z;
    return sum;
}

// Coefficients of dipy's legacy `descoteaux07` basis (m > 0 ↔ sin, m < 0 ↔
// cos, the same phase) rewritten in MRtrix3's basis, in place: ±m swapped.
void descoteaux07_to_mrtrix(std::vector<float>& c, int lmax);

// max over the sphere of |Σ c_i Y_i| is at most Σ_l ‖c_l‖ sqrt((2l+1)/4π)
// (Cauchy–Schwarz and the addition theorem): the glyphs' bounding radius.
double sh_amplitude_bound(const float* c, int lmax);

}  // namespace fiblet::viewer
