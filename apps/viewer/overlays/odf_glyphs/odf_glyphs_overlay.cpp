#include "overlays/odf_glyphs/odf_glyphs_overlay.hpp"

#include <algorithm>
#include <vector>

#include "gl/gpu_bindings.hpp"
#include "overlays/odf_glyphs/glyph_ray.hpp"
#include "gl/shader_program.hpp"
#include "render/vec_ops.hpp"
#include "render/shading_uniforms.hpp"
#include "techniques/draw_technique.hpp"

namespace fiblet::viewer {

OdfGlyphsOverlay::OdfGlyphsOverlay(const GlyphSet& g)
    : program_(build_program({"odf_glyph_boxes.vert.glsl", "odf_glyphs.frag.glsl"}, gpu_binding_defines())),
      glyphs_(g.centers.size()),
      lmax_(g.lmax),
      coefficients_per_glyph_(g.coefficients_per_glyph) {
    // A binding must hold a buffer even with no glyphs.
    const float none[4] = {0, 0, 0, 0};
    coefficients_ = g.coefficients.empty() ? make_buffer(sizeof none, none, 0)
                                           : make_buffer(GLsizeiptr(g.coefficients.size() * sizeof(float)), g.coefficients.data(), 0);
    // glyph_boxes.glsl: centre and radius, then the box's extents (the cube without them).
    std::vector<float> boxes;
    for (std::size_t i = 0; i < g.centers.size(); ++i) {
        const auto e = g.extents.empty() ? std::array<float, 3>{1, 1, 1} : g.extents[i];
        boxes.insert(boxes.end(), {g.centers[i][0], g.centers[i][1], g.centers[i][2], g.centers[i][3], e[0], e[1], e[2], 0.0f});
        const Vec3f c{g.centers[i][0], g.centers[i][1], g.centers[i][2]};
        const Vec3f half{g.centers[i][3] * e[0], g.centers[i][3] * e[1], g.centers[i][3] * e[2]};
        const Vec3f lo = sub(c, half), hi = add(c, half);
        if (!bounds_) bounds_ = std::array<Vec3f, 2>{lo, hi};
        auto& b = *bounds_;
        b[0] = {std::min(b[0].x, lo.x), std::min(b[0].y, lo.y), std::min(b[0].z, lo.z)};
        b[1] = {std::max(b[1].x, hi.x), std::max(b[1].y, hi.y), std::max(b[1].z, hi.z)};
    }
    centers_ = boxes.empty() ? make_buffer(sizeof none, none, 0)
                             : make_buffer(GLsizeiptr(boxes.size() * sizeof(float)), boxes.data(), 0);
    const std::vector<double> inv = glyph_inverse_vandermonde(lmax_);
    const std::vector<float> inv_f(inv.begin(), inv.end());
    const GLuint id = program_.get();
    glProgramUniform1fv(id, uniform(program_, "uInverseVandermonde"), GLsizei(inv_f.size()), inv_f.data());
    glProgramUniform1i(id, uniform(program_, "uLmax"), lmax_);
    glProgramUniform1f(id, uniform(program_, "uTraceRadius"), float(kGlyphTraceRadius));
    glProgramUniform1ui(id, uniform(program_, "uCoefficientsPerGlyph"), GLuint(coefficients_per_glyph_));
    glProgramUniform1f(id, uniform(program_, "uTolerance"), kGlyphRootTolerance);
}

void OdfGlyphsOverlay::draw(const Camera& camera, const RenderOptions& options) {
    if (glyphs_ == 0) return;
    set_shading_uniforms(program_, camera, options);
    glUseProgram(program_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kGlyphCoefficients, coefficients_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kGlyphCenters, centers_.get());
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(kBoxProxyVertices * glyphs_));
    glDisable(GL_CULL_FACE);
}

}  // namespace fiblet::viewer
