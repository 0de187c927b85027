// An image as a region (fiblet/image_mask.hpp): the voxels that count,
// cropped as tckedit crops them, and a summed-area table for box tests.
#include "fiblet/image_mask.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/float_lanes.hpp"
#include "fiblet/error.hpp"

namespace fiblet {
ImageMask::ImageMask(const MaskImage& mask) : path_(mask.geometry.path) {
    const Image& image = mask.geometry;
    std::array<std::int64_t, 3> lo{std::numeric_limits<std::int64_t>::max(), std::numeric_limits<std::int64_t>::max(),
                                   std::numeric_limits<std::int64_t>::max()},
        hi{-1, -1, -1};
    const std::int64_t nx = image.dims[0], ny = image.dims[1], nz = image.dims[2];
    for (std::int64_t k = 0; k < nz; ++k)
        for (std::int64_t j = 0; j < ny; ++j)
            for (std::int64_t i = 0; i < nx; ++i)
                if (mask.at(i, j, k)) {
                    const std::array<std::int64_t, 3> v{i, j, k};
                    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], v[a]), hi[a] = std::max(hi[a], v[a]);
                }
    if (hi[0] < 0) throw Error(Errc::invalid_argument, image.path + ": cannot use the image as a region: it is empty");

    // tckedit keeps one voxel of margin below the occupied box; the same
    // origin gives the same float transform.
    std::array<std::int64_t, 3> bottom{};
    for (int a = 0; a < 3; ++a) {
        bottom[a] = std::max<std::int64_t>(0, lo[a] - 1);
        size_[a] = std::min(image.dims[a] - 1, hi[a] + 1) - bottom[a] + 1;
    }
    inside_.assign(std::size_t(size_[0] * size_[1] * size_[2]), 0);
    const std::int64_t sx = size_[0] + 1, sy = size_[1] + 1;
    prefix_.assign(std::size_t(sx * sy * (size_[2] + 1)), 0);
    auto sat = [&](std::int64_t i, std::int64_t j, std::int64_t k) -> std::uint32_t& {
        return prefix_[std::size_t(i + sx * (j + sy * k))];
    };
    for (std::int64_t k = 0; k < size_[2]; ++k)
        for (std::int64_t j = 0; j < size_[1]; ++j)
            for (std::int64_t i = 0; i < size_[0]; ++i) {
                const bool in = mask.at(i + bottom[0], j + bottom[1], k + bottom[2]);
                inside_[std::size_t(i + size_[0] * (j + size_[1] * k))] = in;
                inside_count_ += in;
                sat(i + 1, j + 1, k + 1) = std::uint32_t(in) + sat(i, j + 1, k + 1) + sat(i + 1, j, k + 1) +
                                           sat(i + 1, j + 1, k) - sat(i, j, k + 1) - sat(i, j + 1, k) -
                                           sat(i + 1, j, k) + sat(i, j, k);
            }

    Affine3x4 cropped = image.voxel_to_world;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) cropped[r][3] += double(bottom[c]) * image.voxel_to_world[r][c];
    to_voxel_exact_ = inverse(cropped);
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) to_voxel_[r][c] = float(to_voxel_exact_[r][c]);

    // World box of the occupied voxels' cells, grown for float rounding.
    const float inf = std::numeric_limits<float>::infinity();
    bounds_ = {{inf, inf, inf}, {-inf, -inf, -inf}};
    double diagonal = 0;
    for (int corner = 0; corner < 8; ++corner) {
        std::array<double, 3> v{};
        for (int a = 0; a < 3; ++a)
            v[a] = double((corner >> a & 1) ? hi[a] - bottom[a] : lo[a] - bottom[a]) + ((corner >> a & 1) ? 0.5 : -0.5);
        const auto w = transform_point(cropped, v);
        bounds_.min = Vec3f{std::min(bounds_.min.x, float(w[0])), std::min(bounds_.min.y, float(w[1])),
                       std::min(bounds_.min.z, float(w[2]))};
        bounds_.max = Vec3f{std::max(bounds_.max.x, float(w[0])), std::max(bounds_.max.y, float(w[1])),
                       std::max(bounds_.max.z, float(w[2]))};
        diagonal = std::max(diagonal, std::abs(w[0]) + std::abs(w[1]) + std::abs(w[2]));
    }
    const float pad = float(1e-4 + 1e-5 * diagonal);
    bounds_.min = Vec3f{bounds_.min.x - pad, bounds_.min.y - pad, bounds_.min.z - pad};
    bounds_.max = Vec3f{bounds_.max.x + pad, bounds_.max.y + pad, bounds_.max.z + pad};
}

std::shared_ptr<const ImageMask> ImageMask::read(const std::string& path) {
    return std::make_shared<const ImageMask>(read_mask_image(path));
}

bool ImageMask::contains_any(const float* p, std::size_t n) const {
    using detail::Floats, detail::Ints;
    std::size_t k = 0;
    // Indices in 32-bit lanes: every grid of fewer than 2^31 voxels.
    if (inside_.size() < (std::size_t{1} << 31))
        for (; k + 4 <= n; k += 4, p += 12) {
            const Floats x = {p[0], p[3], p[6], p[9]}, y = {p[1], p[4], p[7], p[10]}, z = {p[2], p[5], p[8], p[11]};
            Ints ok = ~Ints{}, r[3];
            for (int a = 0; a < 3; ++a) {
                const auto& m = to_voxel_[a];
                const Floats v = m[0] * x + m[1] * y + m[2] * z + m[3];
                // voxel_index, lane by lane: in range (NaN is not), rounded
                // halves away from zero, below the size. Out-of-range lanes
                // convert 0 instead (no float beyond int32 converts).
                const Ints in_range = (v > -1.0f) & (v < float(size_[a]) + 1.0f);
                const Floats v_in = in_range ? v : Floats{};
                const Ints t = __builtin_convertvector(v_in, Ints);  // toward zero
                const Floats frac = v_in - __builtin_convertvector(t, Floats);
                r[a] = t - (frac >= 0.5f) + (frac <= -0.5f);  // a true comparison is -1
                ok &= in_range & (r[a] >= 0) & (r[a] < std::int32_t(size_[a]));
            }
            for (Ints& ra : r) ra &= ok;  // lanes outside the grid index voxel 0 (not read)
            const Ints voxel = r[0] + std::int32_t(size_[0]) * (r[1] + std::int32_t(size_[1]) * r[2]);
            for (int l = 0; l < 4; ++l)
                if (ok[l] && inside_[std::size_t(voxel[l])]) return true;
        }
    for (; k < n; ++k, p += 3)
        if (contains({p[0], p[1], p[2]})) return true;
    return false;
}

std::int64_t ImageMask::occupied(const std::array<std::int64_t, 3>& lo, const std::array<std::int64_t, 3>& hi) const {
    const std::int64_t sx = size_[0] + 1, sy = size_[1] + 1;
    auto s = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
        return std::int64_t(prefix_[std::size_t(i + sx * (j + sy * k))]);
    };
    const std::int64_t x0 = lo[0], y0 = lo[1], z0 = lo[2], x1 = hi[0] + 1, y1 = hi[1] + 1, z1 = hi[2] + 1;
    return s(x1, y1, z1) - s(x0, y1, z1) - s(x1, y0, z1) - s(x1, y1, z0) + s(x0, y0, z1) + s(x0, y1, z0) +
           s(x1, y0, z0) - s(x0, y0, z0);
}

namespace {

// std::int64_t(std::floor(v)) for the voxel coordinates of a box clamped to
// the mask (finite, far inside the int64 range), without a call into libm
// (baseline x86-64 has no rounding instruction; six calls a box were a
// tenth of a mask query's index walk).
std::int64_t floor_to_int(double v) {
    const auto toward_zero = std::int64_t(v);
    return toward_zero - std::int64_t(double(toward_zero) > v);
}

}  // namespace

ImageMask::Overlap ImageMask::classify(const Aabb& box) const {
    const float box_lo[3] = {box.min.x, box.min.y, box.min.z}, box_hi[3] = {box.max.x, box.max.y, box.max.z};
    const float mask_lo[3] = {bounds_.min.x, bounds_.min.y, bounds_.min.z},
                mask_hi[3] = {bounds_.max.x, bounds_.max.y, bounds_.max.z};
    // Clamped to the mask's bounds: finite even for an unbounded block box.
    double centre[3], half[3];
    bool whole_grid = true;  // every point of the box rounds to a voxel of the grid
    for (int a = 0; a < 3; ++a) {
        if (box_hi[a] < mask_lo[a] || box_lo[a] > mask_hi[a]) return Overlap::outside;
        if (box_lo[a] < mask_lo[a] || box_hi[a] > mask_hi[a]) whole_grid = false;
        const double lo = std::max(box_lo[a], mask_lo[a]), hi = std::min(box_hi[a], mask_hi[a]);
        centre[a] = 0.5 * (lo + hi), half[a] = 0.5 * (hi - lo);
    }
    // Voxel-space box of the world box: its centre mapped (transform_point's
    // arithmetic), its half sides through |M| (the box of its eight corners,
    // within double rounding), grown below by a margin that covers the float
    // arithmetic of contains().
    std::array<std::int64_t, 3> lo{}, hi{};
    for (int a = 0; a < 3; ++a) {
        const auto& m = to_voxel_exact_[a];
        const double vc = m[0] * centre[0] + m[1] * centre[1] + m[2] * centre[2] + m[3];
        const double reach = std::abs(m[0]) * half[0] + std::abs(m[1]) * half[1] + std::abs(m[2]) * half[2];
        const double vmin = vc - reach, vmax = vc + reach;
        const double margin = 1e-3 + 1e-6 * std::max(std::abs(vmin), std::abs(vmax));
        const std::int64_t first = floor_to_int(vmin - margin + 0.5), last = floor_to_int(vmax + margin + 0.5);
        if (first < 0 || last >= size_[a]) whole_grid = false;
        lo[a] = std::max<std::int64_t>(first, 0), hi[a] = std::min<std::int64_t>(last, size_[a] - 1);
        if (lo[a] > hi[a]) return Overlap::outside;
    }
    const std::int64_t count = occupied(lo, hi);
    if (count == 0) return Overlap::outside;
    const std::int64_t cells = (hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1);
    return whole_grid && count == cells ? Overlap::inside : Overlap::partial;
}

}  // namespace fiblet
