#include "overlays/odf_glyphs/glyph_ray.hpp"

#include <cmath>
#include <utility>

namespace fiblet::viewer {

double glyph_sample_angle(int i, int lmax) { return M_PI * double(i) / double(lmax + 1); }

std::vector<double> glyph_inverse_vandermonde(int lmax) {
    const int n = lmax + 1;
    std::vector<double> m(std::size_t(n * n)), inv(std::size_t(n * n), 0.0);
    for (int i = 0; i < n; ++i) {
        const double a = glyph_sample_angle(i, lmax);
        for (int j = 0; j < n; ++j) m[std::size_t(i * n + j)] = std::pow(std::cos(a), lmax - j) * std::pow(std::sin(a), j);
        inv[std::size_t(i * n + i)] = 1;
    }
    // Gauss–Jordan with partial pivoting; n <= 13 and the angles spread over
    // half a circle keep M well conditioned.
    for (int col = 0; col < n; ++col) {
        int pivot = col;
        for (int r = col + 1; r < n; ++r)
            if (std::abs(m[std::size_t(r * n + col)]) > std::abs(m[std::size_t(pivot * n + col)])) pivot = r;
        for (int j = 0; j < n; ++j) {
            std::swap(m[std::size_t(col * n + j)], m[std::size_t(pivot * n + j)]);
            std::swap(inv[std::size_t(col * n + j)], inv[std::size_t(pivot * n + j)]);
        }
        const double d = m[std::size_t(col * n + col)];
        for (int j = 0; j < n; ++j) m[std::size_t(col * n + j)] /= d, inv[std::size_t(col * n + j)] /= d;
        for (int r = 0; r < n; ++r) {
            if (r == col) continue;
            const double f = m[std::size_t(r * n + col)];
            for (int j = 0; j < n; ++j) {
                m[std::size_t(r * n + j)] -= f * m[std::size_t(col * n + j)];
                inv[std::size_t(r * n + j)] -= f * inv[std::size_t(col * n + j)];
            }
        }
    }
    return inv;
}

}  // namespace fiblet::viewer
