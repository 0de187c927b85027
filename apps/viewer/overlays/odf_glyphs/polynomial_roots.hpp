// The first root of a polynomial in an interval (Yuksel 2022, "High-
// Performance Polynomial Root Finding for Graphics"): the roots of its
// derivatives, from the linear one up, split the interval into pieces on
// which the next derivative is monotonic, and each piece whose ends differ
// in sign holds exactly one root, found by Newton's method kept inside the
// bracket (bisection when a step leaves it). Templated so that the CPU
// reference runs in double what polynomial_roots.glsl runs in float.
#pragma once

#include <array>
#include <cmath>
#include <optional>

namespace fiblet::viewer {

inline constexpr int kMaxGlyphPolynomialDegree = 26;  // 2 lmax + 2 with lmax 12

// p(x) and p'(x) of q[0] + q[1] x + ... + q[degree] x^degree (Horner).
template <class T>
void polynomial_and_derivative(const T* q, int degree, T x, T& value, T& slope) {
    value = q[degree], slope = 0;
    for (int j = degree - 1; j >= 0; --j) slope = slope * x + value, value = value * x + q[j];
}

// The one root of q in [a, b] when q(a), q(b) differ in sign and q is
// monotonic there; `tolerance` on the step.
template <class T>
T bracketed_newton(const T* q, int degree, T a, T b, T qa, T tolerance) {
    T x = T(0.5) * (a + b);
    for (int i = 0; i < 64; ++i) {
        T v, s;
        polynomial_and_derivative(q, degree, x, v, s);
        if ((v < 0) == (qa < 0)) a = x;
        else b = x;
        T next = s != 0 ? x - v / s : T(0.5) * (a + b);
        if (!(next > a && next < b)) next = T(0.5) * (a + b);
        const T step = next - x;
        x = next;
        if (std::abs(step) <= tolerance) break;
    }
    return x;
}

// The least root of p (coefficients c[0..degree], degree >= 1) in [lo, hi]
// where p changes sign, or nothing. Roots where p only touches zero are
// not roots here (a ray grazing the surface misses it).
template <class T>
std::optional<T> first_root(const T* c, int degree, T lo, T hi, T tolerance) {
    std::array<T, kMaxGlyphPolynomialDegree + 1> q{};
    std::array<T, kMaxGlyphPolynomialDegree> previous{}, current{};
    int previous_count = 0;
    // Level m: the m-th derivative divided by m!, of degree degree - m.
    for (int m = degree - 1; m >= 0; --m) {
        const int d = degree - m;
        T binomial = 1;  // C(j + m, m), from j = 0 up
        for (int j = 0; j <= d; ++j) {
            if (j > 0) binomial = binomial * T(j + m) / T(j);
            q[j] = binomial * c[j + m];
        }
        int count = 0;
        T a = lo, qa, slope;
        polynomial_and_derivative(q.data(), d, a, qa, slope);
        for (int i = 0; i <= previous_count; ++i) {
            const T b = i < previous_count ? previous[i] : hi;
            T qb;
            polynomial_and_derivative(q.data(), d, b, qb, slope);
            if ((qa < 0) != (qb < 0) && b > a) {
                const T root = bracketed_newton(q.data(), d, a, b, qa, tolerance);
                if (m == 0) return root;
                current[count++] = root;
            }
            a = b, qa = qb;
        }
        previous = current, previous_count = count;
    }
    return std::nullopt;
}

}  // namespace fiblet::viewer
