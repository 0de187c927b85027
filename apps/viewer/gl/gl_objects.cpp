#include "gl/gl_objects.hpp"

#include <fmt/core.h>

#include "fiblet/error.hpp"

namespace fiblet::viewer {

GlBuffer make_buffer(GLsizeiptr bytes, const void* data, GLbitfield flags) {
    while (glGetError() != GL_NO_ERROR) {
    }
    GLuint name = 0;
    glCreateBuffers(1, &name);
    GlBuffer buffer(name);
    // Zero-sized storage is an error in GL: keep one word so binding works.
    glNamedBufferStorage(name, bytes > 0 ? bytes : 4, bytes > 0 ? data : nullptr, flags);
    if (const GLenum e = glGetError(); e != GL_NO_ERROR)
        throw Error(Errc::unsupported,
                    fmt::format("the GL driver could not allocate a buffer of {} bytes (GL error 0x{:04x})", bytes, e));
    return buffer;
}

}  // namespace fiblet::viewer
