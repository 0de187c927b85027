// The GL programs of the shared selection and decode, compiled once per
// context (the drawing styles compile their own: techniques/).
#pragma once

#include "gl_objects.hpp"

namespace fiblet::viewer {

struct GpuPrograms {
    // Compiles every program; throws fiblet::Error{unsupported} with the
    // driver's log, or when the context lacks what the shaders need.
    GpuPrograms();

    GlProgram cull;         // cull_blocks.comp.glsl
    GlProgram decode_scan;        // decode_blocks.comp.glsl
    GlProgram decode_sequential;  // decode_blocks_sequential.comp.glsl
};

}  // namespace fiblet::viewer
