#include "transparency/transparent_lines.hpp"

#include "gl/gpu_bindings.hpp"
#include "gl/shader_program.hpp"
#include "render/shading_uniforms.hpp"

namespace fiblet::viewer {

namespace {
constexpr GLsizei kVerticesPerSegment = 6;  // two triangles
}  // namespace

TransparentLines::TransparentLines()
    : program_(build_program({"block_quads.vert.glsl", "transparent_lines.frag.glsl"}, gpu_binding_defines())) {}

void TransparentLines::set_uniforms(const GlProgram& p, const FrameInputs& in) {
    set_shading_uniforms(p, in.camera, in.options);
    GLint viewport[4] = {0, 0, 1, 1};
    glGetIntegerv(GL_VIEWPORT, viewport);
    glProgramUniform2f(p.get(), uniform(p, "uViewportSize"), float(viewport[2]), float(viewport[3]));
}

void TransparentLines::begin_frame(const FrameInputs& in) { set_uniforms(program_, in); }

void TransparentLines::draw_batch(const FrameInputs& in, const DecodedBatch& batch) {
    const GLuint id = program_.get();
    const std::uint32_t segments = in.scene.header().points_per_block;
    glUseProgram(id);
    in.scene.bind(program_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kPoints, batch.points);
    glProgramUniform1i(id, uniform(program_, "uUseList"), in.use_list ? 1 : 0);
    glProgramUniform1ui(id, uniform(program_, "uFirst"), batch.first);
    glProgramUniform1ui(id, uniform(program_, "uSlotSegments"), segments);
    glProgramUniform1ui(id, uniform(program_, "uChunksPerBlock"), 0);
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(kVerticesPerSegment * segments * batch.count));
}

void TransparentLines::draw_chunks(const FrameInputs& in, const DecodedBatch& batch, std::uint32_t chunk_segments,
                                   std::uint32_t chunks_per_block) {
    const GLuint id = program_.get();
    glUseProgram(id);
    in.scene.bind(program_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kPoints, batch.points);
    glProgramUniform1i(id, uniform(program_, "uUseList"), 1);
    glProgramUniform1ui(id, uniform(program_, "uFirst"), batch.first);
    glProgramUniform1ui(id, uniform(program_, "uSlotSegments"), chunk_segments);
    glProgramUniform1ui(id, uniform(program_, "uChunksPerBlock"), chunks_per_block);
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(kVerticesPerSegment * chunk_segments * batch.count));
}

}  // namespace fiblet::viewer
