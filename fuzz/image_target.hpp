// fiblet — the image readers' fuzz target (NIfTI-1/2, gzip'd NIfTI, .mif):
// the first byte picks the format (the readers go by the file name), the
// rest is the file. Only fiblet::Error may be thrown; an image read has
// sizes whose product is its voxel count, finite values and a finite
// transform, and its header alone reads the same geometry. Shared by
// fuzz/image_fuzz.cpp and tests/fuzz_regression_test.cpp.
#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>

#include "fiblet/error.hpp"
#include "fiblet/image.hpp"
#include "fiblet/image_mask.hpp"
#include "fuzz_targets.hpp"

namespace fiblet::fuzz {

inline void check_image(const Image& img, const std::string& path) {
    check(img.dims.size() >= 3, "an image has fewer than three axes");
    std::uint64_t n = 1;
    for (const std::int64_t d : img.dims) {
        check(d >= 1, "an image axis has no voxel");
        n *= std::uint64_t(d);
    }
    check(img.values.size() == n, "an image's values are not its voxel count");
    for (const auto& row : img.voxel_to_world)
        for (const double v : row) check(std::isfinite(v), "a non-finite voxel-to-world transform");
    const Image header = read_image_header(path);
    check(header.dims == img.dims && header.voxel_to_world == img.voxel_to_world && header.values.empty(),
          "the header alone reads another geometry");
}

inline void image_target(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return;
    static MemFile file;
    const std::string contents = file.set(data + 1, size - 1);
    static const char* const kNames[] = {"image.nii", "image.nii.gz", "image.mif"};
    const std::string path = scratch_dir() + "/" + kNames[data[0] % 3];
    if (!std::filesystem::is_symlink(path)) std::filesystem::create_symlink(contents, path);
    try {
        check_image(read_image(path), path);
    } catch (const Error&) {
    }
    try {
        ImageMask::read(path);
    } catch (const Error&) {
    }
}

}  // namespace fiblet::fuzz
