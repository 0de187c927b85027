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
    explicit ImageMask(const Image& image);
    // read_image(path) made into a mask.
    static std::shared_ptr<const ImageMask> read(const std::string& path);

    const std::string& path() const { return path_; }
    std::uint64_t voxels_inside() const { return inside_count_; }
    // World box holding every inside point (a little larger, for rounding).
    const Aabb& bounds() const { return bounds_; }

    bool contains(Vec3f p) const {
        const float x = p.x, y = p.y, z = p.z;
        const auto& m = to_voxel_;
        // Eigen's order in MRtrix (linear part, then the translation), no FMA.
        const float vi = std::round(m[0][0] * x + m[0][1] * y + m[0][2] * z + m[0][3]);
        const float vj = std::round(m[1][0] * x + m[1][1] * y + m[1][2] * z + m[1][3]);
        const float vk = std::round(m[2][0] * x + m[2][1] * y + m[2][2] * z + m[2][3]);
        if (!(vi >= 0 && vj >= 0 && vk >= 0 && vi < float(size_[0]) && vj < float(size_[1]) && vk < float(size_[2])))
            return false;
        return inside_[std::size_t(vi) + std::size_t(size_[0]) * (std::size_t(vj) + std::size_t(size_[1]) * std::size_t(vk))];
    }

    enum class Overlap { outside, partial, inside };
    // outside: no point of `box` is inside the mask; inside: every point is;
    // partial otherwise (conservative both ways).
    Overlap classify(const Aabb& box) const;

private:
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
