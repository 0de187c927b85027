// Compiling and linking the embedded shaders into GL programs.
#pragma once

#include <initializer_list>
#include <string>
#include <string_view>

#include "gl/gl_objects.hpp"

namespace fiblet::viewer {

// Builds a program from embedded shader files, the stage taken from the name
// (*.comp.glsl, *.vert.glsl, *.frag.glsl). `defines` are inserted after the
// #version line. Throws fiblet::Error with the driver's log on failure.
GlProgram build_program(std::initializer_list<std::string_view> shader_names, const std::string& defines = {});

// Location of a uniform (-1 when the driver optimized it away, which
// glUniform* ignores).
inline GLint uniform(const GlProgram& p, const char* name) { return glGetUniformLocation(p.get(), name); }

}  // namespace fiblet::viewer
