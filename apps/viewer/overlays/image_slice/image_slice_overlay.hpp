// A greyscale slice of an image (the first volume of a 4-D one) drawn where
// it lies in the world, as a textured quad with depth: the background the
// fibers and glyphs are read against. Voxels are shown nearest-neighbour,
// grey = (value − min) / (max − min) over the slice.
#pragma once

#include <array>
#include <cstdint>

#include "fiblet/image.hpp"
#include "gl/gl_objects.hpp"
#include "overlays/overlay.hpp"

namespace fiblet::viewer {

// The slice's values and where its corners lie, computed on the CPU.
struct SliceImage {
    int width = 0, height = 0;  // voxels along the slice's first and second in-plane axes
    std::vector<float> values;  // width × height, first axis fastest
    float min = 0, max = 1;
    std::array<std::array<float, 3>, 4> corners{};  // world mm of the grid's outer corners: (0,0), (w,0), (0,h), (w,h)
};
// In-plane axes are (axis + 1) % 3 and (axis + 2) % 3 of the voxel grid.
SliceImage make_slice_image(const Image& image, int axis, std::int64_t index);

class ImageSliceOverlay final : public Overlay {
public:
    explicit ImageSliceOverlay(const SliceImage& slice);
    void draw(const Camera& camera, const RenderOptions& options) override;
    std::optional<std::array<Vec3f, 2>> bounds() const override;

private:
    GlProgram program_;
    GlTexture texture_;
    SliceImage geometry_;
};

}  // namespace fiblet::viewer
