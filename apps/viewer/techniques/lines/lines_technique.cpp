#include "techniques/lines/lines_technique.hpp"

#include "gl/gpu_bindings.hpp"
#include "gl/shader_program.hpp"
#include "render/shading_uniforms.hpp"
#include "voxel_rt/chord_occlusion.hpp"

namespace fiblet::viewer {

LinesTechnique::LinesTechnique()
    : fine_(build_program({"fine_lines.vert.glsl", "lines.frag.glsl"}, gpu_binding_defines())),
      coarse_(build_program({"coarse_lines.vert.glsl", "lines.frag.glsl"}, gpu_binding_defines())) {}

void LinesTechnique::begin_frame(const FrameInputs& in) {
    glLineWidth(in.options.line_width);
    set_shading_uniforms(fine_, in.camera, in.options);
    set_shading_uniforms(coarse_, in.camera, in.options);
    set_occlusion_uniforms(fine_, in.occlusion);
    set_occlusion_uniforms(coarse_, in.occlusion);
}

void LinesTechnique::draw_batch(const FrameInputs& in, const DecodedBatch& batch) {
    glUseProgram(fine_.get());
    in.scene.bind(fine_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kPoints, batch.points);
    glProgramUniform1i(fine_.get(), uniform(fine_, "uUseList"), in.use_list ? 1 : 0);
    glProgramUniform1ui(fine_.get(), uniform(fine_, "uFirst"), batch.first);
    glDrawArrays(GL_LINES, 0, GLsizei(2 * in.scene.header().points_per_block * batch.count));
}

void LinesTechnique::draw_coarse(const FrameInputs& in, std::uint32_t count) {
    glUseProgram(coarse_.get());
    in.scene.bind(coarse_);
    glDrawArrays(GL_LINES, 0, GLsizei(2 * count));
}

}  // namespace fiblet::viewer
