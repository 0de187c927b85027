#include "render/shading_uniforms.hpp"

#include <algorithm>

#include "gl/shader_program.hpp"
#include "render/vec_ops.hpp"
#include "scene/colormaps.hpp"

namespace fiblet::viewer {

CameraBasis camera_basis(const Camera& c) {
    const Vec3f back = normalized(sub(c.position, c.target));
    const Vec3f right = normalized(cross(c.up, back));
    return {right, cross(back, right), back};
}

void set_colormap_uniforms(const GlProgram& p, const RenderOptions& o) {
    const GLuint id = p.get();
    glProgramUniform1i(id, uniform(p, "uPointValues"), o.point_values ? 1 : 0);
    if (!o.point_values) return;
    const ColormapAnchors& a = colormap_anchors(o.colormap);
    glProgramUniform3fv(id, uniform(p, "uColormap"), kColormapAnchors, a[0].data());
    const std::array<float, 2> r = o.value_range.value_or(std::array<float, 2>{0, 1});
    glProgramUniform2f(id, uniform(p, "uValueRange"), r[0], r[1]);
}

void set_shading_uniforms(const GlProgram& p, const Camera& camera, const RenderOptions& o) {
    const GLuint id = p.get();
    const Mat4 vp = view_projection_matrix(camera);
    glProgramUniformMatrix4fv(id, uniform(p, "uViewProjection"), 1, GL_FALSE, vp.data());
    glProgramUniform1i(id, uniform(p, "uColorByDirection"), o.color_by_direction ? 1 : 0);
    glProgramUniform1i(id, uniform(p, "uFiberColors"), o.fiber_colors ? 1 : 0);
    set_colormap_uniforms(p, o);
    glProgramUniform3f(id, uniform(p, "uFixedColor"), o.fixed_color[0], o.fixed_color[1], o.fixed_color[2]);
    glProgramUniform1i(id, uniform(p, "uLighting"), o.lighting ? 1 : 0);
    glProgramUniform1i(id, uniform(p, "uShowNormals"), o.color_by_normal ? 1 : 0);
    glProgramUniform3f(id, uniform(p, "uCameraPosition"), camera.position.x, camera.position.y, camera.position.z);
    // A headlight a little above and to the left of the eye, so that lines
    // facing the viewer are not all equally lit.
    const CameraBasis b = camera_basis(camera);
    const Vec3f light = normalized(add(add(b.back, scale(0.5f, b.up)), scale(-0.35f, b.right)));
    glProgramUniform3f(id, uniform(p, "uLightDirection"), light.x, light.y, light.z);
    glProgramUniform1f(id, uniform(p, "uAmbient"), 0.25f);
    glProgramUniform1f(id, uniform(p, "uDiffuse"), 0.75f);
    glProgramUniform1f(id, uniform(p, "uSpecular"), 0.35f);
    glProgramUniform1f(id, uniform(p, "uShininess"), 24.0f);
    const auto& s = o.slab_plane;
    glProgramUniform4f(id, uniform(p, "uSlabPlane"), s[0], s[1], s[2], s[3]);
    glProgramUniform1f(id, uniform(p, "uSlabHalfWidth"), o.slab_half_width_mm);
    glProgramUniform1f(id, uniform(p, "uGlobalOpacity"), o.opacity);
    glProgramUniform1i(id, uniform(p, "uFiberOpacity"), o.fiber_opacity ? 1 : 0);
    const auto& h = o.highlighted_fibers;
    const GLsizei n = GLsizei(std::min(h.size(), kMaxHighlightedFibers));
    glProgramUniform1i(id, uniform(p, "uHighlightedCount"), n);
    if (n > 0) glProgramUniform1uiv(id, uniform(p, "uHighlighted"), n, h.data());
}

}  // namespace fiblet::viewer
