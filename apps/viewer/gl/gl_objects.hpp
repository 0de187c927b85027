// Owning wrappers of OpenGL object names (moved, never copied), so that every
// buffer, program and query is released with its owner.
#pragma once

#include <epoxy/gl.h>

#include <cstdint>
#include <utility>

namespace fiblet::viewer {

template <void (*Delete)(GLuint)>
class GlName {
public:
    GlName() = default;
    explicit GlName(GLuint name) : name_(name) {}
    ~GlName() { reset(); }
    GlName(GlName&& o) noexcept : name_(std::exchange(o.name_, 0)) {}
    GlName& operator=(GlName&& o) noexcept {
        if (this != &o) reset(), name_ = std::exchange(o.name_, 0);
        return *this;
    }
    GlName(const GlName&) = delete;
    GlName& operator=(const GlName&) = delete;

    GLuint get() const { return name_; }
    explicit operator bool() const { return name_ != 0; }
    void reset() {
        if (name_) Delete(name_);
        name_ = 0;
    }

private:
    GLuint name_ = 0;
};

namespace gl_delete {
inline void buffer(GLuint n) { glDeleteBuffers(1, &n); }
inline void program(GLuint n) { glDeleteProgram(n); }
inline void query(GLuint n) { glDeleteQueries(1, &n); }
inline void texture(GLuint n) { glDeleteTextures(1, &n); }
inline void framebuffer(GLuint n) { glDeleteFramebuffers(1, &n); }
inline void vertex_array(GLuint n) { glDeleteVertexArrays(1, &n); }
}  // namespace gl_delete

using GlBuffer = GlName<gl_delete::buffer>;
using GlProgram = GlName<gl_delete::program>;
using GlQuery = GlName<gl_delete::query>;
using GlTexture = GlName<gl_delete::texture>;
using GlFramebuffer = GlName<gl_delete::framebuffer>;
using GlVertexArray = GlName<gl_delete::vertex_array>;

// A new immutable buffer of `bytes` bytes (glNamedBufferStorage), optionally
// filled from `data`. Throws fiblet::Error{unsupported} when the driver runs
// out of memory.
GlBuffer make_buffer(GLsizeiptr bytes, const void* data, GLbitfield flags);
// The buffer's size in bytes (0 for none).
std::uint64_t buffer_bytes(const GlBuffer& buffer);

}  // namespace fiblet::viewer
