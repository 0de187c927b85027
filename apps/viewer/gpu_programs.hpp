// The viewer's GL programs, compiled once per context.
#pragma once

#include "gl_objects.hpp"

namespace fiblet::viewer {

struct GpuPrograms {
    // Compiles every program; throws fiblet::Error{unsupported} with the
    // driver's log, or when the context lacks what the shaders need.
    GpuPrograms();

    GlProgram cull;         // cull_blocks.comp.glsl
    GlProgram decode;       // decode_blocks.comp.glsl
    GlProgram fine_lines;   // fine_lines.vert.glsl + lines.frag.glsl
    GlProgram coarse_lines; // coarse_lines.vert.glsl + lines.frag.glsl
};

}  // namespace fiblet::viewer
