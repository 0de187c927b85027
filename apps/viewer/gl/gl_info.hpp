// What the current OpenGL context is.
#pragma once

#include <string>

namespace fiblet::viewer {

// The driver's renderer and version strings, e.g. "llvmpipe (LLVM 15.0.6,
// 256 bits), OpenGL 4.5 (Core Profile) Mesa 22.3.6".
std::string current_gl_description();

// Throws fiblet::Error{unsupported} unless the context is OpenGL 4.5 or newer.
void require_gl45();

// Mesa's software rasterizers (llvmpipe, softpipe): the CPU runs the shaders.
bool is_software_renderer();

}  // namespace fiblet::viewer
