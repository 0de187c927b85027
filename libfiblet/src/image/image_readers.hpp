// Internal: the readers behind read_image(), one per format, and the
// geometry rules they share (MRtrix3's, see fiblet/image.hpp).
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "fiblet/image.hpp"

namespace fiblet::detail {

// What a reader does with the voxels: nothing (the header alone: dims,
// spacing, voxel_to_world), every volume as float (Image::values), or the
// first volume as mask counts (MaskImage::counts, whose rule voxel_counts is).
struct VoxelOutput {
    std::vector<float>* values = nullptr;
    std::vector<std::uint8_t>* counts = nullptr;
    void put(std::size_t at, float v) const {
        if (values) (*values)[at] = v;
        else (*counts)[at] = voxel_counts(v);
    }
    // Sized for `voxels` more (grown as data arrives, never to a header's claim).
    void grow_to(std::size_t voxels) const {
        if (values) values->resize(voxels);
        else counts->resize(voxels);
    }
    static bool voxel_counts(float v) { return std::isfinite(v) && std::round(v) != 0; }
};

Image read_nifti(const std::string& path, VoxelOutput out = {});
Image read_mif(const std::string& path, VoxelOutput out = {});

// Axes in `rotation` (3x3 part; translation in column 3) scaled by the voxel
// sizes: the voxel -> world map. Cosine vectors that are not unit length are
// normalised first, their length going into the voxel size (MRtrix's
// Header::sanitise_transform).
Affine3x4 voxel_to_world(Affine3x4 rotation, std::array<double, 3>& spacing);
// MRtrix's transform for an image without one: identity axes, the grid's
// centre at the origin.
Affine3x4 centred_transform(const Image& image);

// Error{image_format} naming the file when the voxel -> world transform
// cannot be inverted.
void check_transform(const Image& image);

// Dimensions and byte counts: Error{image_format} for a size of 0 or one
// whose voxel count overflows.
std::size_t voxel_count(const std::string& path, const std::vector<std::int64_t>& dims);

}  // namespace fiblet::detail
