// read_image(): the format by the file name; geometry helpers.
#include <Eigen/Dense>
#include <cmath>
#include <limits>

#include "fiblet/error.hpp"
#include "fiblet/image.hpp"
#include "image/image_readers.hpp"
#include "io/regular_input.hpp"

namespace fiblet {

namespace {
bool ends_with(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}
}  // namespace

std::int64_t Image::volumes() const {
    std::int64_t n = 1;
    for (std::size_t a = 3; a < dims.size(); ++a) n *= dims[a];
    return n;
}

namespace {
Image read_any(const std::string& path, detail::VoxelOutput out) {
    detail::require_regular_input(path);
    if (ends_with(path, ".nii") || ends_with(path, ".nii.gz")) return detail::read_nifti(path, out);
    if (ends_with(path, ".mif") || ends_with(path, ".mih")) return detail::read_mif(path, out);
    if (ends_with(path, ".mif.gz"))
        throw Error(Errc::unsupported, path + ": compressed .mif.gz images are not supported: "
                                              "mrconvert it to .mif or .nii.gz");
    throw Error(Errc::unsupported, path + ": not an image fiblet reads (expected .nii, .nii.gz or .mif)");
}
}  // namespace

Image read_image(const std::string& path) {
    std::vector<float> values;
    Image image = read_any(path, {&values, nullptr});
    image.values = std::move(values);
    return image;
}
Image read_image_header(const std::string& path) { return read_any(path, {}); }
MaskImage read_mask_image(const std::string& path) {
    MaskImage mask;
    mask.geometry = read_any(path, {nullptr, &mask.counts});
    return mask;
}

std::array<double, 3> transform_point(const Affine3x4& m, const std::array<double, 3>& v) {
    std::array<double, 3> out{};
    for (int r = 0; r < 3; ++r) out[r] = m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2] + m[r][3];
    return out;
}

// Eigen's closed-form 3x3 inverse, as MRtrix3's transforms use (so a
// world-to-voxel rounding matches tckedit's).
Affine3x4 inverse(const Affine3x4& m) {
    Eigen::Matrix3d linear;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) linear(r, c) = m[r][c];
    const double det = linear.determinant();
    if (!std::isfinite(det) || det == 0)
        throw Error(Errc::image_format, "the image's voxel-to-world transform is singular or not finite");
    const Eigen::Matrix3d inv = linear.inverse();
    const Eigen::Vector3d shift = -(inv * Eigen::Vector3d(m[0][3], m[1][3], m[2][3]));
    Affine3x4 out{};
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) out[r][c] = inv(r, c);
        out[r][3] = shift(r);
    }
    return out;
}

namespace detail {

Affine3x4 voxel_to_world(Affine3x4 m, std::array<double, 3>& spacing) {
    for (int c = 0; c < 3; ++c) {
        const double length = std::sqrt(m[0][c] * m[0][c] + m[1][c] * m[1][c] + m[2][c] * m[2][c]);
        if (std::abs(length - 1.0) > 1e-6 && length > 0) {
            for (int r = 0; r < 3; ++r) m[r][c] /= length;
            spacing[c] *= length;
        }
    }
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) m[r][c] *= spacing[c];
    return m;
}

Affine3x4 centred_transform(const Image& image) {
    Affine3x4 m{};
    for (int r = 0; r < 3; ++r) {
        m[r][r] = 1;
        m[r][3] = -0.5 * double(image.dims[r] - 1) * image.spacing[r];
    }
    return m;
}

void check_transform(const Image& image) {
    // Every entry finite, both ways: a NaN or infinite offset (a header's
    // qoffset or srow) would put every voxel nowhere.
    auto finite = [](const Affine3x4& m) {
        for (const auto& row : m)
            for (const double v : row)
                if (!std::isfinite(v)) return false;
        return true;
    };
    try {
        if (!finite(image.voxel_to_world) || !finite(inverse(image.voxel_to_world)))
            throw Error(Errc::image_format, "the image's voxel-to-world transform is not finite");
    } catch (const Error& e) {
        throw Error(Errc::image_format, image.path + ": " + e.what());
    }
}

std::size_t voxel_count(const std::string& path, const std::vector<std::int64_t>& dims) {
    std::size_t n = 1;
    for (const std::int64_t d : dims) {
        if (d < 1) throw Error(Errc::image_format, path + ": invalid image size (an axis of " + std::to_string(d) + " voxels)");
        if (n > std::numeric_limits<std::size_t>::max() / 16 / std::size_t(d))
            throw Error(Errc::image_format, path + ": image too large (voxel count overflows)");
        n *= std::size_t(d);
    }
    return n;
}

}  // namespace detail
}  // namespace fiblet
