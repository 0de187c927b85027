#include "overlays/sh_basis/sh_basis.hpp"

#include <cmath>
#include <utility>

namespace fiblet::viewer {

std::optional<ShBasis> parse_sh_basis(const std::string& name) {
    if (name == "mrtrix" || name == "tournier") return ShBasis::mrtrix;
    if (name == "descoteaux07") return ShBasis::descoteaux07;
    return std::nullopt;
}

int sh_lmax_for_count(long count) {
    for (int lmax = 0; lmax <= kMaxShLmax; lmax += 2)
        if (sh_coefficient_count(lmax) == count) return lmax;
    return -1;
}

void descoteaux07_to_mrtrix(std::vector<float>& c, int lmax) {
    for (int l = 2; l <= lmax; l += 2)
        for (int m = 1; m <= l; ++m)  // dipy: sin(mφ) at +m, cos(mφ) at −m
            std::swap(c[std::size_t(sh_index(l, m))], c[std::size_t(sh_index(l, -m))]);
}

double sh_amplitude_bound(const float* c, int lmax) {
    double bound = 0;
    for (int l = 0; l <= lmax; l += 2) {
        double norm2 = 0;
        for (int m = -l; m <= l; ++m) norm2 += double(c[sh_index(l, m)]) * double(c[sh_index(l, m)]);
        bound += std::sqrt(norm2) * std::sqrt((2 * l + 1) / (4 * M_PI));
    }
    return bound;
}

}  // namespace fiblet::viewer
