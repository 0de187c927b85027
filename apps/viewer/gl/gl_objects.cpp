#include "gl/gl_objects.hpp"

#include <fmt/core.h>

#include <algorithm>

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

std::uint64_t buffer_bytes(const GlBuffer& buffer) {
    if (!buffer) return 0;
    GLint64 size = 0;
    glGetNamedBufferParameteri64v(buffer.get(), GL_BUFFER_SIZE, &size);
    return std::uint64_t(std::max<GLint64>(size, 0));
}

}  // namespace fiblet::viewer
