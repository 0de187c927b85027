// The glyphs of one slice of an SH image, prepared on the CPU: per glyph
// its centre (the voxel centre, world mm), its bounding radius in mm and its
// coefficients in glyph units (divided by the amplitude bound, so that the
// glyph lies inside the unit sphere and its box is the cube of that radius).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "fiblet/image.hpp"
#include "overlays/sh_basis/sh_basis.hpp"

namespace fiblet::viewer {

struct GlyphSetOptions {
    int axis = 2;
    std::int64_t index = 0;
    int lmax = -1;        // -1: the image's; else at most the image's (higher degrees dropped)
    ShBasis basis = ShBasis::mrtrix;
    float scale = 1;      // the largest glyph of the slice spans scale × the smallest voxel size
    bool tight_boxes = true;
};

struct GlyphSet {
    int lmax = 0;
    int coefficients_per_glyph = 1;
    std::vector<std::array<float, 4>> centers;  // xyz world mm, w: bounding radius (mm)
    // Half sizes of each glyph's box along x, y, z in glyph units (<= 1):
    // the paper's tight box (largest |f(u) u_i|, sampled and refined, grown
    // 2.5 %) within the bound's cube. Empty: the cube (1, 1, 1).
    std::vector<std::array<float, 3>> extents;
    std::vector<float> coefficients;            // glyph units, coefficients_per_glyph each, MRtrix3 basis
    std::vector<std::array<std::int64_t, 3>> voxels;  // each glyph's voxel (tests)
    double mm_per_unit(std::size_t glyph) const { return centers[glyph][3]; }
};

// Throws fiblet::Error{invalid_argument} when the image is not an SH image
// (4-D with 1, 6, 15, ..., 91 volumes) or lmax is not even / above its own.
// Voxels whose coefficients are all zero have no glyph.
// `tight_boxes`: compute GlyphSet::extents (else the bound's cubes).
GlyphSet make_glyph_set(const Image& image, const GlyphSetOptions& options);

// The tight box of one glyph (coefficients in glyph units): for each axis i
// the largest |f(u)| |u_i| over `directions` (unit, a half sphere: glyphs
// are symmetric; `values` f there, or empty to evaluate them), refined by a
// shrinking local search on the sphere from the best sample (5 rounds),
// grown by 2.5 % and capped at 1.
std::array<float, 3> glyph_box_extents(const std::vector<float>& coefficients, int lmax,
                                       const std::vector<std::array<double, 3>>& directions,
                                       std::vector<double> values = {});
std::vector<std::array<double, 3>> fibonacci_half_sphere(int n);

}  // namespace fiblet::viewer
