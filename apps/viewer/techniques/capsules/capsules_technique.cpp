#include "techniques/capsules/capsules_technique.hpp"

#include "gpu_bindings.hpp"
#include "shader_program.hpp"
#include "shading_uniforms.hpp"
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
    glUseProgram(draw_.get());
    in.scene.bind(draw_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kPoints, batch.points);
    glProgramUniform1i(draw_.get(), uniform(draw_, "uUseList"), in.use_list ? 1 : 0);
    glProgramUniform1ui(draw_.get(), uniform(draw_, "uFirst"), batch.first);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(kBoxProxyVertices * in.scene.header().points_per_block * batch.count));
    glDisable(GL_CULL_FACE);
}

void CapsulesTechnique::draw_coarse(const FrameInputs& in, std::uint32_t count) { coarse_lines_.draw_coarse(in, count); }

}  // namespace fiblet::viewer
