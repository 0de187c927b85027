#include "techniques/tubes/tubes_technique.hpp"

#include <algorithm>

#include "gl/gpu_bindings.hpp"
#include "gl/shader_program.hpp"
#include "render/shading_uniforms.hpp"
#include "voxel_rt/chord_occlusion.hpp"

namespace fiblet::viewer {

namespace {
constexpr std::uint64_t kPieceBytes = 8 * 16;  // TubePiece: eight vec4
}  // namespace

TubesTechnique::TubesTechnique(float tangent_scale)
    : tangent_scale_(tangent_scale),
      build_(build_program({"tube_pieces.comp.glsl"}, gpu_binding_defines())),
      draw_(build_program({"tube_boxes.vert.glsl", "tubes.frag.glsl"}, gpu_binding_defines())),
      piece_buffer_limit_(max_storage_buffer_bytes()) {}

void TubesTechnique::begin_frame(const FrameInputs& in) {
    set_shading_uniforms(draw_, in.camera, in.options);
    set_occlusion_uniforms(draw_, in.occlusion);
    coarse_lines_.begin_frame(in);
}

std::uint32_t TubesTechnique::build_pieces(const FrameInputs& in, const DecodedBatch& batch) {
    return build_pieces(in, batch, in.use_list, 0, 0, 0, batch.count);
}

std::uint32_t TubesTechnique::segments_per_slot(const FrameInputs& in, std::uint32_t chunk_segments,
                                                std::uint32_t chunks_per_block) const {
    const FftHeader& h = in.scene.header();
    const std::uint32_t s = tube_node_spacing(tube_radius_for_spacing(in.scene, in.options), h.step * h.scaling);
    return chunks_per_block ? tube_segments_per_chunk(chunk_segments, s) : tube_segments_per_slot(h.points_per_block, s);
}

std::uint32_t TubesTechnique::build_pieces(const FrameInputs& in, const DecodedBatch& batch, bool use_list,
                                           std::uint32_t chunk_segments, std::uint32_t chunks_per_block,
                                           std::uint32_t first_slot, std::uint32_t slots) {
    const FftHeader& h = in.scene.header();
    const std::uint32_t s = tube_node_spacing(tube_radius_for_spacing(in.scene, in.options), h.step * h.scaling);
    const std::uint32_t per_slot = segments_per_slot(in, chunk_segments, chunks_per_block);
    const std::uint64_t segments = std::uint64_t(slots) * per_slot;
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
    glProgramUniform1i(id, uniform(build_, "uPointValues"), in.options.point_values ? 1 : 0);
    glProgramUniform1ui(id, uniform(build_, "uChunksPerBlock"), chunks_per_block);
    glProgramUniform1ui(id, uniform(build_, "uChunkSegments"), std::max(chunk_segments, 1u));
    glProgramUniform1ui(id, uniform(build_, "uFirst"), batch.first);
    glProgramUniform1ui(id, uniform(build_, "uCount"), batch.count);
    glProgramUniform1ui(id, uniform(build_, "uFirstSlot"), first_slot);
    glProgramUniform1ui(id, uniform(build_, "uNodeSpacing"), s);
    glProgramUniform1ui(id, uniform(build_, "uSegmentsPerSlot"), per_slot);
    glProgramUniform1f(id, uniform(build_, "uRadius"), in.options.tube_radius_mm);
    glProgramUniform1i(id, uniform(build_, "uFiberRadii"), in.options.fiber_radii ? 1 : 0);
    glProgramUniform1f(id, uniform(build_, "uTangentScale"), tangent_scale_);
    glDispatchCompute(GLuint((segments + 63) / 64), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    return std::uint32_t(2 * segments);
}

void TubesTechnique::draw_slots(const FrameInputs& in, const DecodedBatch& batch, bool use_list,
                                std::uint32_t chunk_segments, std::uint32_t chunks_per_block) {
    // The pieces of a run of slots must fit one storage buffer: a batch of
    // 32,768 blocks of 254 points (16-bit files) at 26 segments each takes
    // 190 MB of pieces, more than llvmpipe's 128 MiB.
    const std::uint64_t slot_bytes = 2 * std::uint64_t(segments_per_slot(in, chunk_segments, chunks_per_block)) * kPieceBytes;
    const std::uint32_t per_run = std::uint32_t(std::clamp<std::uint64_t>(piece_buffer_limit_ / slot_bytes, 1, batch.count));
    for (std::uint32_t first = 0; first < batch.count; first += per_run) {
        draw_pieces(build_pieces(in, batch, use_list, chunk_segments, chunks_per_block, first,
                                 std::min(per_run, batch.count - first)));
        // The next run overwrites the pieces this draw reads.
        if (first + per_run < batch.count) glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
}

void TubesTechnique::draw_batch(const FrameInputs& in, const DecodedBatch& batch) {
    if (batch.count == 0) return;
    draw_slots(in, batch, in.use_list, 0, 0);
}

void TubesTechnique::draw_chunks(const FrameInputs& in, const DecodedBatch& batch, std::uint32_t chunk_segments,
                                 std::uint32_t chunks_per_block) {
    // Every slot builds the segments of its chunk of its block: the pieces
    // keep the order of the slots.
    if (batch.count == 0) return;
    draw_slots(in, batch, true, chunk_segments, chunks_per_block);
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
