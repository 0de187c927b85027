// Ray tracing one SH glyph (Peters, Patel, Usher, Johnson, "Ray Tracing
// Spherical Harmonics Glyphs", VMV 2023). In glyph units (centre at the
// origin, coefficients scaled so that |f| <= 1, hence the glyph inside the
// unit sphere) the surface is ‖x‖ = |f(x/‖x‖)|. With the homogenized
// f_h(x) = ‖x‖^k f(x/‖x‖), a polynomial of degree k = lmax, it is
// F(x) = f_h(x)² − ‖x‖^{2k+2} = 0, and along a ray a polynomial of degree
// 2k+2. Written x = X e1 + Y e2 in the plane of the ray and the centre
// (e2 the ray's direction, e1 towards the ray's closest point, X = ρ its
// distance), f_h = Σ a_j X^{k−j} Y^j: the a_j are the values of f at k+1
// unit vectors of that plane times a fixed inverse matrix. Templated: the
// CPU reference in double, glyph_ray.glsl the same steps in float.
#pragma once

#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "overlays/odf_glyphs/polynomial_roots.hpp"
#include "overlays/sh_basis/sh_basis.hpp"

namespace fiblet::viewer {

// Angle of sample i of k+1 in the plane: α_i = π i / (k + 1), half a circle.
double glyph_sample_angle(int i, int lmax);
// The inverse of M_ij = cos^{k−j} α_i sin^j α_i ((k+1)², row-major), so that
// a = M⁻¹ (f(u_0), ..., f(u_k)).
std::vector<double> glyph_inverse_vandermonde(int lmax);

template <class T>
using Vec3 = std::array<T, 3>;

// The radius (glyph units) of the sphere whose chord the root finder
// searches. The glyph lies within the unit sphere but may touch it (an
// isotropic ODF is the unit sphere itself): there F vanishes at the chord's
// ends and the sign test at an end sees rounding noise, missing the hit.
// Past the unit sphere F < 0 for certain, so the chord's ends are outside.
inline constexpr double kGlyphTraceRadius = 1.0625;

template <class T>
struct GlyphHit {
    T t;              // along the ray, glyph units
    Vec3<T> normal;   // unit, outward
};

template <class T>
T dot3(const Vec3<T>& a, const Vec3<T>& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// The frame of the ray's plane: e2 = d, e1 towards the closest point (any
// normal of d when the ray meets the centre), e3 = e1 × e2.
template <class T>
struct RayPlane {
    T t0, rho;
    Vec3<T> e1, e2, e3;
};
template <class T>
RayPlane<T> ray_plane(const Vec3<T>& o, const Vec3<T>& d) {
    RayPlane<T> p;
    p.t0 = -dot3(o, d);
    Vec3<T> c{o[0] + p.t0 * d[0], o[1] + p.t0 * d[1], o[2] + p.t0 * d[2]};
    p.rho = std::sqrt(dot3(c, c));
    if (p.rho > T(1e-7)) p.e1 = {c[0] / p.rho, c[1] / p.rho, c[2] / p.rho};
    else {
        const Vec3<T> a = std::abs(d[0]) < T(0.9) ? Vec3<T>{1, 0, 0} : Vec3<T>{0, 1, 0};
        Vec3<T> n{a[1] * d[2] - a[2] * d[1], a[2] * d[0] - a[0] * d[2], a[0] * d[1] - a[1] * d[0]};
        const T len = std::sqrt(dot3(n, n));
        p.e1 = {n[0] / len, n[1] / len, n[2] / len};
    }
    p.e2 = d;
    p.e3 = {p.e1[1] * d[2] - p.e1[2] * d[1], p.e1[2] * d[0] - p.e1[0] * d[2], p.e1[0] * d[1] - p.e1[1] * d[0]};
    return p;
}

// f_h along the plane: a_j of f_h(X e1 + Y e2) = Σ a_j X^{k−j} Y^j.
template <class T, class Coefficients>
std::array<T, kMaxShLmax + 1> plane_polynomial(const Coefficients& b, int k, const std::vector<double>& minv,
                                               const RayPlane<T>& p) {
    std::array<T, kMaxShLmax + 1> f{}, a{};
    for (int i = 0; i <= k; ++i) {
        const T alpha = T(glyph_sample_angle(i, k)), c = std::cos(alpha), s = std::sin(alpha);
        f[i] = sh_value<T>(b, k, c * p.e1[0] + s * p.e2[0], c * p.e1[1] + s * p.e2[1], c * p.e1[2] + s * p.e2[2]);
    }
    for (int j = 0; j <= k; ++j)
        for (int i = 0; i <= k; ++i) a[j] += T(minv[std::size_t(j * (k + 1) + i)]) * f[i];
    return a;
}

// f_h(x) = ‖x‖^k f(x/‖x‖).
template <class T, class Coefficients>
T homogenized(const Coefficients& b, int k, const Vec3<T>& x) {
    const T r = std::sqrt(dot3(x, x));
    if (r == 0) return 0;
    return std::pow(r, T(k)) * sh_value<T>(b, k, x[0] / r, x[1] / r, x[2] / r);
}

// The outward unit normal at x ≠ 0 (glyph units) of the level set of
// F(x) = f_h(x)² − ‖x‖^{2k+2} through x, in closed form. With x = r u,
// f_h = r^k f(u) is homogeneous of degree k (Euler: its radial derivative is
// k f_h / r) and across u it changes as r^{k−1} ∇_S f(u), so
//   ∇f_h = r^{k−1} (k f u + ∇_S f),
//   ∇F = 2 f_h ∇f_h − (2k+2) r^{2k} x = 2 r^{2k−1} ((k f² − (k+1) r²) u + f ∇_S f),
// and −∇F (outward: F grows inwards) lies along ((k+1) r² − k f²) u − f ∇_S f.
// On the surface (r = |f|) that is r² u − f ∇_S f ∝ x − (f/r) ∇_S f, the
// paper's formula; off it (the root finder's tolerance) still exactly −∇F.
// One SH evaluation with its gradient (sh_value_and_gradient).
template <class T, class Coefficients>
Vec3<T> glyph_normal(const Coefficients& b, int k, const Vec3<T>& x) {
    const T r = std::sqrt(dot3(x, x));
    if (!(r > 0)) return {0, 0, 0};
    const Vec3<T> u{x[0] / r, x[1] / r, x[2] / r};
    T g[3];
    const T f = sh_value_and_gradient<T>(b, k, u[0], u[1], u[2], g);
    const T radial = T(k + 1) * r * r - T(k) * f * f;
    Vec3<T> n{radial * u[0] - f * g[0], radial * u[1] - f * g[1], radial * u[2] - f * g[2]};
    const T len = std::sqrt(dot3(n, n));
    if (len > 0) n = {n[0] / len, n[1] / len, n[2] / len};
    return n;
}

// The first hit of the ray o + t d (unit d, glyph units) with t in
// [t_min, ∞), or nothing. `tolerance`: the root finder's step tolerance.
template <class T, class Coefficients>
std::optional<GlyphHit<T>> trace_glyph(const Coefficients& b, int k, const std::vector<double>& minv,
                                       const Vec3<T>& o, const Vec3<T>& d, T t_min, T tolerance) {
    const RayPlane<T> p = ray_plane(o, d);
    const T radius = T(kGlyphTraceRadius);
    if (p.rho >= radius) return std::nullopt;  // the glyph lies inside the unit sphere
    const std::array<T, kMaxShLmax + 1> a = plane_polynomial(b, k, minv, p);
    // g(s) = f_h(ρ e1 + s e2) = Σ c_j s^j with c_j = a_j ρ^{k−j}; s = t − t0.
    std::array<T, kMaxShLmax + 1> c{};
    T power = 1;
    for (int j = k; j >= 0; --j) c[j] = a[j] * power, power *= p.rho;
    // F(s) = g(s)² − (ρ² + s²)^{k+1}.
    const int degree = 2 * k + 2;
    std::array<T, kMaxGlyphPolynomialDegree + 1> poly{};
    for (int i = 0; i <= k; ++i)
        for (int j = 0; j <= k; ++j) poly[i + j] += c[i] * c[j];
    T binomial = 1, rho2 = p.rho * p.rho;
    for (int i = 0; i <= k + 1; ++i) {
        if (i > 0) binomial = binomial * T(k + 2 - i) / T(i);
        poly[2 * i] -= binomial * std::pow(rho2, T(k + 1 - i));
    }
    // The chord of the trace sphere, from t_min on.
    const T half = std::sqrt(std::max(T(0), radius * radius - rho2));
    const T lo = std::max(-half, t_min - p.t0), hi = half;
    if (!(lo < hi)) return std::nullopt;
    const std::optional<T> s = first_root(poly.data(), degree, lo, hi, tolerance);
    if (!s) return std::nullopt;
    GlyphHit<T> hit;
    hit.t = p.t0 + *s;
    const T X = p.rho, Y = *s;
    hit.normal = glyph_normal<T>(b, k, Vec3<T>{X * p.e1[0] + Y * p.e2[0], X * p.e1[1] + Y * p.e2[1], X * p.e1[2] + Y * p.e2[2]});
    return hit;
}

}  // namespace fiblet::viewer
