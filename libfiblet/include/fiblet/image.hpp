// fiblet — voxel images: NIfTI-1/2 (.nii, .nii.gz, through libnifti) and
// MRtrix3 .mif. Masks for region selection read them; the viewer's
// background slices and ODF glyphs (4-D spherical-harmonic images) will too.
//
// Geometry follows MRtrix3 3.0 (so that a mask means what it means to
// tckedit): voxel (i, j, k) has its centre at voxel_to_world * (i, j, k, 1),
// world (scanner) millimetres, RAS+. NIfTI: the sform when sform_code is
// set, else the qform, else MRtrix's default (identity axes, grid centred on
// the origin). .mif: the "transform:" rows times the "vox:" sizes.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace fiblet {

using Affine3x4 = std::array<std::array<double, 4>, 3>;

struct Image {
    std::string path;
    // Sizes of the axes, at least three (x, y, z, then volumes: 4-D images
    // such as SH coefficients; further axes, if any, follow).
    std::vector<std::int64_t> dims;
    std::array<double, 3> spacing{1, 1, 1};  // voxel size in mm (x, y, z)
    Affine3x4 voxel_to_world{};              // voxel indices -> world mm
    // Voxel values, x fastest, then y, z, then the volumes (NIfTI's order,
    // whatever the file's layout). Integer data is scaled by the file's
    // intensity scaling (NIfTI scl_slope/scl_inter, .mif "scaling:"); float
    // data is used as stored, as MRtrix 3.0 reads it (nibabel would scale it).
    std::vector<float> values;

    std::int64_t volumes() const;  // product of the sizes after the third
    std::size_t offset(std::int64_t i, std::int64_t j, std::int64_t k, std::int64_t volume = 0) const {
        return std::size_t(i + dims[0] * (j + dims[1] * (k + dims[2] * volume)));
    }
    float at(std::int64_t i, std::int64_t j, std::int64_t k, std::int64_t volume = 0) const {
        return values[offset(i, j, k, volume)];
    }
};

// An image read as a mask, as MRtrix3 reads a bool image: voxel (i, j, k) of
// the first volume counts when its value (scaled as read_image scales it)
// rounds to non-zero; NaN and infinity do not. One byte a voxel, the voxels
// never widened to float; a NIfTI file's later volumes are not read.
struct MaskImage {
    Image geometry;                    // path, dims, spacing, voxel_to_world; no values
    std::vector<std::uint8_t> counts;  // 0 or 1 per voxel of the first volume, x fastest
    bool at(std::int64_t i, std::int64_t j, std::int64_t k) const { return counts[geometry.offset(i, j, k)]; }
};
MaskImage read_mask_image(const std::string& path);

// Reads an image by its name: .nii / .nii.gz (NIfTI-1 or NIfTI-2), .mif
// (MRtrix3, data in the same file or, for .mih, in the file it names).
// Throws Error{io} when it cannot be read, Error{image_format} when it is
// malformed, Error{unsupported} for a valid image fiblet does not read
// (complex voxels, .mif.gz, another extension).
Image read_image(const std::string& path);
// The same without the voxels (values empty): dims, spacing, voxel_to_world.
Image read_image_header(const std::string& path);

// world = M * (v, 1) and its inverse (throws Error{image_format} when the
// 3x3 part is singular).
std::array<double, 3> transform_point(const Affine3x4& m, const std::array<double, 3>& v);
Affine3x4 inverse(const Affine3x4& m);

}  // namespace fiblet
