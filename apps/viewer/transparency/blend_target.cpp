#include "transparency/blend_target.hpp"

namespace fiblet::viewer {

void BlendTarget::ensure_size(int width, int height) {
    if (width == width_ && height == height_ && framebuffer_) return;
    GLuint t = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    glTextureStorage2D(t, 1, GL_RGBA32F, width, height);
    color_ = GlTexture(t);
    GLuint f = 0;
    glCreateFramebuffers(1, &f);
    framebuffer_ = GlFramebuffer(f);
    glNamedFramebufferTexture(f, GL_COLOR_ATTACHMENT0, t, 0);
    width_ = width, height_ = height;
}

void BlendTarget::begin(RenderTarget& target, bool clear, const std::array<float, 3>& background) {
    ensure_size(target.width(), target.height());
    if (clear) {
        const float rgba[4] = {background[0], background[1], background[2], 1.0f};
        glClearNamedFramebufferfv(framebuffer_.get(), GL_COLOR, 0, rgba);
    } else {
        glBlitNamedFramebuffer(target.framebuffer(), framebuffer_.get(), 0, 0, width_, height_, 0, 0, width_, height_,
                               GL_COLOR_BUFFER_BIT, GL_NEAREST);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.get());
    glViewport(0, 0, width_, height_);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
}

void BlendTarget::resolve(RenderTarget& target) {
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glEnable(GL_DEPTH_TEST);
    // Only the colour attachment takes the blit (the fiber indices are
    // integers); then the target draws both again, as RenderTarget set it.
    const GLuint fb = target.framebuffer();
    glNamedFramebufferDrawBuffer(fb, GL_COLOR_ATTACHMENT0);
    glBlitNamedFramebuffer(framebuffer_.get(), fb, 0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT,
                           GL_NEAREST);
    const GLenum draw_buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glNamedFramebufferDrawBuffers(fb, 2, draw_buffers);
    glBindFramebuffer(GL_FRAMEBUFFER, fb);
}

}  // namespace fiblet::viewer
