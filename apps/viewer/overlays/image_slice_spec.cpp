#include "overlays/image_slice_spec.hpp"

#include <cmath>
#include <cstdlib>

#include "fiblet/error.hpp"

namespace fiblet::viewer {

SliceSpec parse_slice_spec(const std::string& text, const char* option) {
    const std::size_t colon = text.find(':');
    const std::string axis = text.substr(0, colon);
    SliceSpec s;
    if (axis == "x" || axis == "0") s.axis = 0;
    else if (axis == "y" || axis == "1") s.axis = 1;
    else if (axis == "z" || axis == "2") s.axis = 2;
    else throw Error(Errc::invalid_argument, std::string(option) + ": '" + text + "' is not AXIS:INDEX (AXIS x, y or z)");
    if (colon == std::string::npos) return s;
    const std::string index = text.substr(colon + 1);
    char* end = nullptr;
    const long long v = std::strtoll(index.c_str(), &end, 10);
    if (index.empty() || *end != '\0' || v < 0)
        throw Error(Errc::invalid_argument, std::string(option) + ": '" + index + "' is not a voxel index");
    s.index = v;
    return s;
}

std::int64_t slice_index(const SliceSpec& s, const Image& image, const char* option) {
    const std::int64_t size = image.dims[std::size_t(s.axis)];
    const std::int64_t i = s.index < 0 ? size / 2 : s.index;
    if (i >= size)
        throw Error(Errc::invalid_argument, std::string(option) + ": index " + std::to_string(i) + " is outside 0.." +
                                                std::to_string(size - 1) + " of " + image.path);
    return i;
}

WorldPlane slice_plane(const Image& image, int axis, std::int64_t index) {
    // The normal is the gradient of the voxel coordinate along `axis`: row
    // `axis` of the world-to-voxel matrix.
    const Affine3x4 inv = inverse(image.voxel_to_world);
    const auto& row = inv[std::size_t(axis)];
    const double len = std::sqrt(row[0] * row[0] + row[1] * row[1] + row[2] * row[2]);
    WorldPlane p;
    p.normal = {row[0] / len, row[1] / len, row[2] / len};
    p.offset = (double(index) - row[3]) / len;
    return p;
}

}  // namespace fiblet::viewer
