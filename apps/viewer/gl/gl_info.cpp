#include "gl/gl_info.hpp"

#include <epoxy/gl.h>

#include "fiblet/error.hpp"

namespace fiblet::viewer {

namespace {
std::string gl_string(GLenum e) {
    const auto* s = reinterpret_cast<const char*>(glGetString(e));
    return s ? s : "?";
}
}  // namespace

std::string current_gl_description() { return gl_string(GL_RENDERER) + ", OpenGL " + gl_string(GL_VERSION); }

void require_gl45() {
    if (epoxy_gl_version() < 45)
        throw Error(Errc::unsupported, "the viewer needs OpenGL 4.5; this context offers " + current_gl_description());
}

bool is_software_renderer() {
    const std::string renderer = gl_string(GL_RENDERER);
    for (const char* software : {"llvmpipe", "softpipe", "swrast"})
        if (renderer.find(software) != std::string::npos) return true;
    return false;
}

}  // namespace fiblet::viewer
