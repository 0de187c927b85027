// fiblet — an image used as a region of interest, with MRtrix3 tckedit's
// meaning (3.0: src/dwi/tractography/roi.h): a point is inside when the
// voxel nearest to it (world -> voxel in float, indices rounded) lies in the
// image and its value, in the first volume, rounds to non-zero (values of
// 0.5 and above count; NaN does not).
//
// For the block index, a mask also answers "may a box of the world hold an
// inside point / are all its points inside?" in constant time: the box is
// mapped to the voxel indices it can round to, and a summed-area table over
// the occupied voxels (cropped to their bounding box) counts them.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fiblet/geometry.hpp"
#include "fiblet/image.hpp"
#include "fiblet/view.hpp"

namespace fiblet {

class ImageMask {
public:
    // Throws Error{invalid_argument} when no voxel is inside (tckedit: "image is empty").
    explicit ImageMask(const MaskImage& mask);
    // read_mask_image(path) made into a mask.
    static std::shared_ptr<const ImageMask> read(const std::string& path);

    const std::string& path() const { return path_; }
    std::uint64_t voxels_inside() const { return inside_count_; }
    // World box holding every inside point (a little larger, for rounding).
    const Aabb& bounds() const { return bounds_; }

    bool contains(Vec3f p) const {
        const float x = p.x, y = p.y, z = p.z;
        const auto& m = to_voxel_;
        // Eigen's order in MRtrix (linear part, then the translation), no FMA.
        std::size_t i, j, k;
        return voxel_index(m[0][0] * x + m[0][1] * y + m[0][2] * z + m[0][3], size_[0], i) &&
               voxel_index(m[1][0] * x + m[1][1] * y + m[1][2] * z + m[1][3], size_[1], j) &&
               voxel_index(m[2][0] * x + m[2][1] * y + m[2][2] * z + m[2][3], size_[2], k) &&
               inside_[i + std::size_t(size_[0]) * (j + std::size_t(size_[1]) * k)];
    }

    // Whether any of n points (xyz triplets) is inside: contains(), four
    // points at a time.
    bool contains_any(const float* xyz, std::size_t n) const;

    enum class Overlap { outside, partial, inside };
    // outside: no point of `box` is inside the mask; inside: every point is;
    // partial otherwise (conservative both ways).
    Overlap classify(const Aabb& box) const;

private:
    // std::round(v) (halves away from zero) when it is an index below
    // `size`: MRtrix's rounding, without a call into libm.
    static bool voxel_index(float v, std::int64_t size, std::size_t& index) {
        if (!(v > -1.0f && v < float(size) + 1.0f)) return false;  // NaN too
        const auto t = std::int64_t(v);  // toward zero
        const float frac = v - float(t);  // exact: |v| is small
        const std::int64_t r = t + (frac >= 0.5f) - (frac <= -0.5f);
        if (r < 0 || r >= size) return false;
        index = std::size_t(r);
        return true;
    }
    std::int64_t occupied(const std::array<std::int64_t, 3>& lo, const std::array<std::int64_t, 3>& hi) const;

    std::string path_;
    std::array<std::array<float, 4>, 3> to_voxel_{};  // world -> voxel of the cropped grid, float as MRtrix
    Affine3x4 to_voxel_exact_{};                      // the same in double, for box tests
    std::array<std::int64_t, 3> size_{};              // cropped grid
    std::vector<std::uint8_t> inside_;                // per voxel of the cropped grid
    std::vector<std::uint32_t> prefix_;               // summed-area table, (size + 1)^3
    std::uint64_t inside_count_ = 0;
    Aabb bounds_{};
};

}  // namespace fiblet
