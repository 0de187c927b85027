#include "overlays/odf_glyphs/glyph_set.hpp"

#include <algorithm>
#include <cmath>

#include "fiblet/error.hpp"

namespace fiblet::viewer {

// Near-uniform directions on the half sphere z > 0 (a glyph is
// symmetric): a Fibonacci lattice.
std::vector<std::array<double, 3>> fibonacci_half_sphere(int n) {
    std::vector<std::array<double, 3>> dirs;
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double z = (double(i) + 0.5) / double(n), r = std::sqrt(1 - z * z), phi = golden * double(i);
        dirs.push_back({r * std::cos(phi), r * std::sin(phi), z});
    }
    return dirs;
}

std::array<float, 3> glyph_box_extents(const std::vector<float>& c, int lmax,
                                       const std::vector<std::array<double, 3>>& directions, std::vector<double> values) {
    const auto extent = [&](const std::array<double, 3>& u, int axis) {
        return std::abs(sh_value<double>(c, lmax, u[0], u[1], u[2]) * u[std::size_t(axis)]);
    };
    if (values.empty())
        for (const auto& u : directions) values.push_back(sh_value<double>(c, lmax, u[0], u[1], u[2]));
    std::array<float, 3> out{};
    for (int axis = 0; axis < 3; ++axis) {
        std::array<double, 3> best{};
        double best_value = -1;
        for (std::size_t i = 0; i < directions.size(); ++i) {
            const double v = std::abs(values[i] * directions[i][std::size_t(axis)]);
            if (v > best_value) best_value = v, best = directions[i];
        }
        // A local search on the sphere: steps along two tangents, each round
        // half as long, starting at the lattice's spacing.
        double step = 2.0 / std::sqrt(double(directions.size()));
        for (int round = 0; round < 5; ++round, step *= 0.5) {
            const std::array<double, 3> a = std::abs(best[0]) < 0.9 ? std::array<double, 3>{1, 0, 0} : std::array<double, 3>{0, 1, 0};
            std::array<double, 3> t1{best[1] * a[2] - best[2] * a[1], best[2] * a[0] - best[0] * a[2], best[0] * a[1] - best[1] * a[0]};
            const double n1 = std::sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
            for (double& x : t1) x /= n1;
            const std::array<double, 3> t2{best[1] * t1[2] - best[2] * t1[1], best[2] * t1[0] - best[0] * t1[2], best[0] * t1[1] - best[1] * t1[0]};
            for (int k = 0; k < 8; ++k) {
                const double angle = M_PI * k / 4;
                std::array<double, 3> u;
                for (int i = 0; i < 3; ++i) u[std::size_t(i)] = best[std::size_t(i)] + step * (std::cos(angle) * t1[std::size_t(i)] + std::sin(angle) * t2[std::size_t(i)]);
                const double n = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
                for (double& x : u) x /= n;
                const double v = extent(u, axis);
                if (v > best_value) best_value = v, best = u;
            }
        }
        out[std::size_t(axis)] = float(std::min(1.0, 1.025 * best_value));
    }
    return out;
}

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
    const auto dirs = fibonacci_half_sphere(512);
    // The basis at the sampled directions, once: f there is then a product.
    const int count = sh_coefficient_count(lmax);
    std::vector<double> basis(dirs.size() * std::size_t(count));
    for (int j = 0; j < count; ++j) {
        std::vector<float> unit(std::size_t(count), 0.0f);
        unit[std::size_t(j)] = 1;
        for (std::size_t i = 0; i < dirs.size(); ++i)
            basis[i * std::size_t(count) + std::size_t(j)] = sh_value<double>(unit, lmax, dirs[i][0], dirs[i][1], dirs[i][2]);
    }
    std::vector<double> values(dirs.size());
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
            for (std::size_t i = 0; i < dirs.size(); ++i) {
                double f = 0;
                for (int j = 0; j < count; ++j) f += basis[i * std::size_t(count) + std::size_t(j)] * double(c[std::size_t(j)]);
                values[i] = f / bound;  // in glyph units
                peak = std::max(peak, std::abs(f));
            }
            const auto centre = transform_point(image.voxel_to_world, {double(voxel[0]), double(voxel[1]), double(voxel[2])});
            set.centers.push_back({float(centre[0]), float(centre[1]), float(centre[2]), float(bound)});
            for (int i = 0; i < set.coefficients_per_glyph; ++i) set.coefficients.push_back(float(c[std::size_t(i)] / bound));
            set.voxels.push_back(voxel);
            if (o.tight_boxes)
                set.extents.push_back(glyph_box_extents(
                    std::vector<float>(set.coefficients.end() - set.coefficients_per_glyph, set.coefficients.end()), lmax, dirs,
                    values));
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
