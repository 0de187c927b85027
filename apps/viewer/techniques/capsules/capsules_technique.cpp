#include "techniques/capsules/capsules_technique.hpp"

#include "gl/gpu_bindings.hpp"
#include "gl/shader_program.hpp"
#include "render/shading_uniforms.hpp"
#include "voxel_rt/chord_occlusion.hpp"

namespace fiblet::viewer {

CapsulesTechnique::CapsulesTechnique()
    : draw_(build_program({"capsule_boxes.vert.glsl", "capsules.frag.glsl"}, gpu_binding_defines())) {}

void CapsulesTechnique::begin_frame(const FrameInputs& in) {
    set_shading_uniforms(draw_, in.camera, in.options);
    set_occlusion_uniforms(draw_, in.occlusion);
    glProgramUniform1f(draw_.get(), uniform(draw_, "uRadius"), in.options.tube_radius_mm);
    glProgramUniform1i(draw_.get(), uniform(draw_, "uFiberRadii"), in.options.fiber_radii ? 1 : 0);
    coarse_lines_.begin_frame(in);
}

void CapsulesTechnique::draw_batch(const FrameInputs& in, const DecodedBatch& batch) {
    draw_slots(in, batch, in.use_list, in.scene.header().points_per_block, 0);
}

void CapsulesTechnique::draw_chunks(const FrameInputs& in, const DecodedBatch& batch, std::uint32_t chunk_segments,
                                    std::uint32_t chunks_per_block) {
    draw_slots(in, batch, true, chunk_segments, chunks_per_block);
}

void CapsulesTechnique::draw_slots(const FrameInputs& in, const DecodedBatch& batch, bool use_list,
                                   std::uint32_t slot_segments, std::uint32_t chunks_per_block) {
    const GLuint id = draw_.get();
    glUseProgram(id);
    in.scene.bind(draw_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kPoints, batch.points);
    glProgramUniform1i(id, uniform(draw_, "uUseList"), use_list ? 1 : 0);
    glProgramUniform1ui(id, uniform(draw_, "uFirst"), batch.first);
    glProgramUniform1ui(id, uniform(draw_, "uSlotSegments"), slot_segments);
    glProgramUniform1ui(id, uniform(draw_, "uChunksPerBlock"), chunks_per_block);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(kBoxProxyVertices * slot_segments * batch.count));
    glDisable(GL_CULL_FACE);
}

void CapsulesTechnique::draw_coarse(const FrameInputs& in, std::uint32_t count) { coarse_lines_.draw_coarse(in, count); }

}  // namespace fiblet::viewer
