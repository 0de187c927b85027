#include "overlays/odf_glyphs/glyph_set.hpp"

#include <algorithm>
#include <cmath>

#include "fiblet/error.hpp"

namespace fiblet::viewer {

namespace {

// Near-uniform directions on the half sphere (a glyph is symmetric): a
// Fibonacci lattice, to estimate each glyph's largest radius for the scale.
std::vector<std::array<double, 3>> fibonacci_half_sphere(int n) {
    std::vector<std::array<double, 3>> dirs;
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double z = (double(i) + 0.5) / double(n), r = std::sqrt(1 - z * z), phi = golden * double(i);
        dirs.push_back({r * std::cos(phi), r * std::sin(phi), z});
    }
    return dirs;
}

}  // namespace

GlyphSet make_glyph_set(const Image& image, const GlyphSetOptions& o) {
    const int image_lmax = image.dims.size() >= 4 ? sh_lmax_for_count(long(image.volumes())) : -1;
    if (image_lmax < 0)
        throw Error(Errc::invalid_argument, image.path + ": not an SH image (4-D with 1, 6, 15, 28, 45, 66 or 91 volumes)");
    const int lmax = o.lmax < 0 ? image_lmax : o.lmax;
    if (lmax % 2 || lmax > image_lmax)
        throw Error(Errc::invalid_argument, "--odf-lmax must be even and at most the image's lmax " + std::to_string(image_lmax));
    GlyphSet set;
    set.lmax = lmax;
    set.coefficients_per_glyph = sh_coefficient_count(lmax);
    const auto dirs = fibonacci_half_sphere(256);
    std::vector<double> largest;  // sampled max |f| of each glyph
    std::vector<float> c(std::size_t(sh_coefficient_count(image_lmax)));
    const std::int64_t nu = image.dims[std::size_t((o.axis + 1) % 3)], nv = image.dims[std::size_t((o.axis + 2) % 3)];
    for (std::int64_t v = 0; v < nv; ++v)
        for (std::int64_t u = 0; u < nu; ++u) {
            std::array<std::int64_t, 3> voxel{};
            voxel[std::size_t(o.axis)] = o.index;
            voxel[std::size_t((o.axis + 1) % 3)] = u, voxel[std::size_t((o.axis + 2) % 3)] = v;
            for (std::size_t i = 0; i < c.size(); ++i) c[i] = image.at(voxel[0], voxel[1], voxel[2], std::int64_t(i));
            if (o.basis == ShBasis::descoteaux07) descoteaux07_to_mrtrix(c, image_lmax);
            const double bound = sh_amplitude_bound(c.data(), lmax);
            if (!(bound > 0) || !std::isfinite(bound)) continue;
            double peak = 0;
            for (const auto& d : dirs) peak = std::max(peak, std::abs(sh_value<double>(c, lmax, d[0], d[1], d[2])));
            const auto centre = transform_point(image.voxel_to_world, {double(voxel[0]), double(voxel[1]), double(voxel[2])});
            set.centers.push_back({float(centre[0]), float(centre[1]), float(centre[2]), float(bound)});
            for (int i = 0; i < set.coefficients_per_glyph; ++i) set.coefficients.push_back(float(c[std::size_t(i)] / bound));
            set.voxels.push_back(voxel);
            largest.push_back(peak);
        }
    // One mm-per-unit factor for the slice, so that glyphs compare: the
    // largest glyph spans `scale` voxels (radius half of it).
    const double peak = largest.empty() ? 1.0 : *std::max_element(largest.begin(), largest.end());
    const double voxel = *std::min_element(image.spacing.begin(), image.spacing.end());
    const double mm_per_amplitude = peak > 0 ? double(o.scale) * 0.5 * voxel / peak : 0.0;
    for (auto& g : set.centers) g[3] = float(double(g[3]) * mm_per_amplitude);
    return set;
}

}  // namespace fiblet::viewer
