// The GL programs of the shared selection and decode, compiled once per
// context (the drawing styles compile their own: techniques/).
#pragma once

#include "fiblet_viewer/gpu_decoder.hpp"
#include "gl/gl_objects.hpp"

namespace fiblet::viewer {

struct GpuPrograms {
    // Compiles every program; throws fiblet::Error{unsupported} with the
    // driver's log, or when the context lacks what the shaders need.
    GpuPrograms();

    GlProgram cull;         // cull_blocks.comp.glsl
    // The decoders, each built for one block layout (WIDE_BLOCKS 0: 8-bit,
    // 1: 16-bit; scene_buffers.glsl): a code is read per point, in their
    // inner loop, where a branch on the layout would cost (llvmpipe runs
    // both sides of a branch).
    GlProgram decode_scan;        // decode_blocks.comp.glsl
    GlProgram decode_sequential;  // decode_blocks_sequential.comp.glsl
    GlProgram decode_scan_wide;
    GlProgram decode_sequential_wide;
    const GlProgram& decoder(GpuDecoder kind, bool wide_blocks) const;
};

}  // namespace fiblet::viewer
