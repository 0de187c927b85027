// Internal: the readers behind read_image(), one per format, and the
// geometry rules they share (MRtrix3's, see fiblet/image.hpp).
#pragma once

#include <string>

#include "fiblet/image.hpp"

namespace fiblet::detail {

// `values`: false reads the header alone (dims, spacing, voxel_to_world).
Image read_nifti(const std::string& path, bool values = true);
Image read_mif(const std::string& path, bool values = true);

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
