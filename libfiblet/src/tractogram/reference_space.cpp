// The space of a reference image, for tractograms that carry none (.tck):
// what tckconvert and DIPY take as a reference.
#include "fiblet/error.hpp"
#include "fiblet/image.hpp"
#include "fiblet/tractogram_space.hpp"

namespace fiblet {

TractogramSpace space_of_image(const std::string& path) {
    const Image header = read_image_header(path);
    for (int a = 0; a < 3; ++a)
        if (header.dims[std::size_t(a)] > 0x7fffffff)
            throw Error(Errc::unsupported, path + ": a reference image's dimensions must fit in 32 bits");
    Affine a = kIdentityAffine;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) a[std::size_t(4 * r + c)] = header.voxel_to_world[r][c];
    return TractogramSpace::from_affine(a, {int(header.dims[0]), int(header.dims[1]), int(header.dims[2])});
}

}  // namespace fiblet
