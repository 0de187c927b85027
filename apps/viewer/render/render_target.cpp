#include "render/render_target.hpp"

#include <algorithm>
#include <string>

#include "fiblet/error.hpp"

namespace fiblet::viewer {

RenderTarget::RenderTarget(int width, int height) { resize(width, height); }

void RenderTarget::resize(int width, int height) {
    if (width == width_ && height == height_ && framebuffer_) return;
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    if (width < 1 || height < 1 || width > max_size || height > max_size)
        throw Error(Errc::invalid_argument, "image size " + std::to_string(width) + "x" + std::to_string(height) +
                                                " is outside 1.." + std::to_string(max_size) + " pixels a side");
    width_ = width, height_ = height;
    allocate();
}

void RenderTarget::allocate() {
    while (glGetError() != GL_NO_ERROR) {
    }
    auto texture = [&](GLenum format) {
        GLuint t = 0;
        glCreateTextures(GL_TEXTURE_2D, 1, &t);
        glTextureStorage2D(t, 1, format, width_, height_);
        return GlTexture(t);
    };
    color_ = texture(GL_RGBA8);
    fibers_ = texture(GL_R32UI);
    depth_ = texture(GL_DEPTH_COMPONENT24);
    GLuint f = 0;
    glCreateFramebuffers(1, &f);
    framebuffer_ = GlFramebuffer(f);
    glNamedFramebufferTexture(f, GL_COLOR_ATTACHMENT0, color_.get(), 0);
    glNamedFramebufferTexture(f, GL_COLOR_ATTACHMENT1, fibers_.get(), 0);
    glNamedFramebufferTexture(f, GL_DEPTH_ATTACHMENT, depth_.get(), 0);
    const GLenum draw_buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glNamedFramebufferDrawBuffers(f, 2, draw_buffers);
    if (glGetError() == GL_OUT_OF_MEMORY)
        throw Error(Errc::unsupported, "the GL driver has no memory for a " + std::to_string(width_) + "x" +
                                           std::to_string(height_) + " image");
    if (glCheckNamedFramebufferStatus(f, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw Error(Errc::unsupported, "the GL driver cannot render to an RGBA8 + R32UI + depth framebuffer");
}

std::vector<std::uint8_t> RenderTarget::read_rgba() const {
    const std::size_t row = std::size_t(width_) * 4;
    std::vector<std::uint8_t> bottom_up(row * std::size_t(height_));
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTextureImage(color_.get(), 0, GL_RGBA, GL_UNSIGNED_BYTE, GLsizei(bottom_up.size()), bottom_up.data());
    std::vector<std::uint8_t> out(bottom_up.size());
    for (int y = 0; y < height_; ++y)
        std::copy_n(&bottom_up[std::size_t(height_ - 1 - y) * row], row, &out[std::size_t(y) * row]);
    return out;
}

std::vector<std::uint32_t> RenderTarget::read_fibers(int x, int y, int w, int h) const {
    if (x < 0 || y < 0 || w < 1 || h < 1 || x + w > width_ || y + h > height_)
        throw Error(Errc::invalid_argument, "fiber buffer rectangle outside the image");
    std::vector<std::uint32_t> bottom_up(std::size_t(w) * std::size_t(h));
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    // GL rows start at the bottom of the image.
    glGetTextureSubImage(fibers_.get(), 0, x, height_ - y - h, 0, w, h, 1, GL_RED_INTEGER, GL_UNSIGNED_INT,
                         GLsizei(bottom_up.size() * 4), bottom_up.data());
    std::vector<std::uint32_t> out(bottom_up.size());
    for (int r = 0; r < h; ++r)
        std::copy_n(&bottom_up[std::size_t(h - 1 - r) * std::size_t(w)], w, &out[std::size_t(r) * std::size_t(w)]);
    return out;
}

std::vector<float> RenderTarget::read_depth() const {
    std::vector<float> bottom_up(std::size_t(width_) * std::size_t(height_));
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTextureImage(depth_.get(), 0, GL_DEPTH_COMPONENT, GL_FLOAT, GLsizei(bottom_up.size() * 4), bottom_up.data());
    std::vector<float> out(bottom_up.size());
    for (int r = 0; r < height_; ++r)
        std::copy_n(&bottom_up[std::size_t(height_ - 1 - r) * std::size_t(width_)], width_,
                    &out[std::size_t(r) * std::size_t(width_)]);
    return out;
}

void RenderTarget::begin_frame(bool clear, const std::array<float, 3>& background) const {
    const GLuint fb = framebuffer();
    glBindFramebuffer(GL_FRAMEBUFFER, fb);
    glViewport(0, 0, width_, height_);
    if (!clear) return;
    const float color[4] = {background[0], background[1], background[2], 1.0f};
    const GLuint no_fiber[4] = {0, 0, 0, 0};
    const float far_depth = 1.0f;
    glClearNamedFramebufferfv(fb, GL_COLOR, 0, color);
    glClearNamedFramebufferuiv(fb, GL_COLOR, 1, no_fiber);
    glClearNamedFramebufferfv(fb, GL_DEPTH, 0, &far_depth);
}

}  // namespace fiblet::viewer
