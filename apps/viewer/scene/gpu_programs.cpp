#include "scene/gpu_programs.hpp"

#include <string>

#include "fiblet/error.hpp"
#include "gl/gpu_bindings.hpp"
#include "gl/shader_program.hpp"

namespace fiblet::viewer {

namespace {
void require_limit(GLenum name, GLint at_least, const char* what) {
    GLint v = 0;
    glGetIntegerv(name, &v);
    if (v < at_least)
        throw Error(Errc::unsupported, std::string("the GL driver offers too few ") + what + " (" +
                                           std::to_string(v) + ", the viewer needs " + std::to_string(at_least) + ")");
}
}  // namespace

GpuPrograms::GpuPrograms() {
    require_limit(GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS, GLint(binding::kStorageCount),
                  "shader storage buffer bindings");
    require_limit(GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS, 5, "shader storage blocks in vertex shaders");
    require_limit(GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS, 8, "shader storage blocks in compute shaders");
    const std::string defines = gpu_binding_defines();
    cull = build_program({"cull_blocks.comp.glsl"}, defines);
    decode_scan = build_program({"decode_blocks.comp.glsl"}, defines + "#define WIDE_BLOCKS 0\n");
    decode_sequential = build_program({"decode_blocks_sequential.comp.glsl"}, defines + "#define WIDE_BLOCKS 0\n");
    decode_scan_wide = build_program({"decode_blocks.comp.glsl"}, defines + "#define WIDE_BLOCKS 1\n");
    decode_sequential_wide = build_program({"decode_blocks_sequential.comp.glsl"}, defines + "#define WIDE_BLOCKS 1\n");
}

const GlProgram& GpuPrograms::decoder(GpuDecoder kind, bool wide_blocks) const {
    if (kind == GpuDecoder::scan) return wide_blocks ? decode_scan_wide : decode_scan;
    return wide_blocks ? decode_sequential_wide : decode_sequential;
}

}  // namespace fiblet::viewer
