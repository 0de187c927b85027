#include "techniques/tubes/tubes_technique.hpp"

#include <algorithm>

#include "gpu_bindings.hpp"
#include "shader_program.hpp"
#include "shading_uniforms.hpp"
#include "voxel_rt/chord_occlusion.hpp"

namespace fiblet::viewer {

namespace {
constexpr std::uint64_t kPieceBytes = 7 * 16;  // TubePiece: seven vec4
}  // namespace

TubesTechnique::TubesTechnique(float tangent_scale)
    : tangent_scale_(tangent_scale),
      build_(build_program({"tube_pieces.comp.glsl"}, gpu_binding_defines())),
      draw_(build_program({"tube_boxes.vert.glsl", "tubes.frag.glsl"}, gpu_binding_defines())) {}

void TubesTechnique::begin_frame(const FrameInputs& in) {
    set_shading_uniforms(draw_, in.camera, in.options);
    set_occlusion_uniforms(draw_, in.occlusion);
    coarse_lines_.begin_frame(in);
}

std::uint32_t TubesTechnique::build_pieces(const FrameInputs& in, const DecodedBatch& batch) {
    return build_pieces(in, batch, in.use_list, 0, 0);
}

std::uint32_t TubesTechnique::build_pieces(const FrameInputs& in, const DecodedBatch& batch, bool use_list,
                                           std::uint32_t chunk_segments, std::uint32_t chunks_per_block) {
    const FftHeader& h = in.scene.header();
    const std::uint32_t s = tube_node_spacing(tube_radius_for_spacing(in.scene, in.options), h.step * h.scaling);
    const std::uint32_t segments_per_slot =
        chunks_per_block ? tube_segments_per_chunk(chunk_segments, s) : tube_segments_per_slot(h.points_per_block, s);
    const std::uint64_t segments = std::uint64_t(batch.count) * segments_per_slot;
    if (pieces_capacity_ < 2 * segments) {
        pieces_ = make_buffer(GLsizeiptr(2 * segments * kPieceBytes), nullptr, 0);
        pieces_capacity_ = 2 * segments;
    }
    const GLuint id = build_.get();
    glUseProgram(id);
    in.scene.bind(build_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kPoints, batch.points);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kTangents, batch.tangents);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kTubePieces, pieces_.get());
    glProgramUniform1i(id, uniform(build_, "uUseList"), use_list ? 1 : 0);
    glProgramUniform1ui(id, uniform(build_, "uChunksPerBlock"), chunks_per_block);
    glProgramUniform1ui(id, uniform(build_, "uChunkSegments"), std::max(chunk_segments, 1u));
    glProgramUniform1ui(id, uniform(build_, "uFirst"), batch.first);
    glProgramUniform1ui(id, uniform(build_, "uCount"), batch.count);
    glProgramUniform1ui(id, uniform(build_, "uNodeSpacing"), s);
    glProgramUniform1ui(id, uniform(build_, "uSegmentsPerSlot"), segments_per_slot);
    glProgramUniform1f(id, uniform(build_, "uRadius"), in.options.tube_radius_mm);
    glProgramUniform1i(id, uniform(build_, "uFiberRadii"), in.options.fiber_radii ? 1 : 0);
    glProgramUniform1f(id, uniform(build_, "uTangentScale"), tangent_scale_);
    glDispatchCompute(GLuint((segments + 63) / 64), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    return std::uint32_t(2 * segments);
}

void TubesTechnique::draw_batch(const FrameInputs& in, const DecodedBatch& batch) {
    if (batch.count == 0) return;
    draw_pieces(build_pieces(in, batch));
}

void TubesTechnique::draw_chunks(const FrameInputs& in, const DecodedBatch& batch, std::uint32_t chunk_segments,
                                 std::uint32_t chunks_per_block) {
    // Every slot builds its block's segments, those of other chunks empty
    // (drawn as nothing): the pieces keep the order of the slots.
    if (batch.count == 0) return;
    draw_pieces(build_pieces(in, batch, true, chunk_segments, chunks_per_block));
}

void TubesTechnique::draw_pieces(std::uint32_t pieces) {
    glUseProgram(draw_.get());
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(pieces * kBoxProxyVertices));
    glDisable(GL_CULL_FACE);
}

void TubesTechnique::draw_coarse(const FrameInputs& in, std::uint32_t count) { coarse_lines_.draw_coarse(in, count); }

}  // namespace fiblet::viewer
