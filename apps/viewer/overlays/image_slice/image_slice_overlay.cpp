#include "overlays/image_slice/image_slice_overlay.hpp"

#include <algorithm>

#include "gl/shader_program.hpp"
#include "render/shading_uniforms.hpp"

namespace fiblet::viewer {

SliceImage make_slice_image(const Image& image, int axis, std::int64_t index) {
    const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
    SliceImage s;
    s.width = int(image.dims[std::size_t(ua)]), s.height = int(image.dims[std::size_t(va)]);
    s.values.resize(std::size_t(s.width) * std::size_t(s.height));
    for (int v = 0; v < s.height; ++v)
        for (int u = 0; u < s.width; ++u) {
            std::array<std::int64_t, 3> voxel{};
            voxel[std::size_t(axis)] = index, voxel[std::size_t(ua)] = u, voxel[std::size_t(va)] = v;
            s.values[std::size_t(v) * std::size_t(s.width) + std::size_t(u)] = image.at(voxel[0], voxel[1], voxel[2], 0);
        }
    const auto [lo, hi] = std::minmax_element(s.values.begin(), s.values.end());
    s.min = *lo, s.max = *hi > *lo ? *hi : *lo + 1;
    // Voxel centres are integer coordinates; the grid's edges lie half a voxel out.
    for (int c = 0; c < 4; ++c) {
        std::array<double, 3> voxel{};
        voxel[std::size_t(axis)] = double(index);
        voxel[std::size_t(ua)] = (c & 1) ? s.width - 0.5 : -0.5;
        voxel[std::size_t(va)] = (c & 2) ? s.height - 0.5 : -0.5;
        const auto w = transform_point(image.voxel_to_world, voxel);
        s.corners[std::size_t(c)] = {float(w[0]), float(w[1]), float(w[2])};
    }
    return s;
}

ImageSliceOverlay::ImageSliceOverlay(const SliceImage& slice)
    : program_(build_program({"image_slice.vert.glsl", "image_slice.frag.glsl"})), geometry_(slice) {
    GLuint t = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    texture_ = GlTexture(t);
    glTextureStorage2D(t, 1, GL_R32F, slice.width, slice.height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage2D(t, 0, 0, 0, slice.width, slice.height, GL_RED, GL_FLOAT, slice.values.data());
    glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureParameteri(t, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(t, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    const GLuint id = program_.get();
    float corners[12];
    for (int c = 0; c < 4; ++c)
        for (int i = 0; i < 3; ++i) corners[3 * c + i] = slice.corners[std::size_t(c)][std::size_t(i)];
    glProgramUniform3fv(id, uniform(program_, "uCorners"), 4, corners);
    glProgramUniform2f(id, uniform(program_, "uWindow"), slice.min, slice.max);
    glProgramUniform1i(id, uniform(program_, "uSlice"), 0);
}

void ImageSliceOverlay::draw(const Camera& camera, const RenderOptions&) {
    const Mat4 vp = view_projection_matrix(camera);
    glProgramUniformMatrix4fv(program_.get(), uniform(program_, "uViewProjection"), 1, GL_FALSE, vp.data());
    glUseProgram(program_.get());
    glBindTextureUnit(0, texture_.get());
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
}

std::optional<std::array<Vec3f, 2>> ImageSliceOverlay::bounds() const {
    std::array<Vec3f, 2> b;
    for (int c = 0; c < 4; ++c) {
        const auto& p = geometry_.corners[std::size_t(c)];
        b[0] = c == 0 ? Vec3f{p[0], p[1], p[2]} : Vec3f{std::min(b[0].x, p[0]), std::min(b[0].y, p[1]), std::min(b[0].z, p[2])};
        b[1] = c == 0 ? Vec3f{p[0], p[1], p[2]} : Vec3f{std::max(b[1].x, p[0]), std::max(b[1].y, p[1]), std::max(b[1].z, p[2])};
    }
    return b;
}

}  // namespace fiblet::viewer
