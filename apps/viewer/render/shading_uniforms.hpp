// The lighting and colour uniforms every drawing style's fragment shader
// shares (uViewProjection, uColorByDirection, uFiberColors, uFixedColor, uLighting,
// uCameraPosition, uLightDirection, uAmbient, uDiffuse, uSpecular,
// uShininess) and the --slab clip (uSlabPlane, uSlabHalfWidth): one
// headlight, set the same way for every technique.
#pragma once

#include "fiblet/view.hpp"
#include "gl/gl_objects.hpp"
#include "fiblet_viewer/render_options.hpp"

namespace fiblet::viewer {

void set_shading_uniforms(const GlProgram& program, const Camera& camera, const RenderOptions& options);
// The per-point values' colour map (uPointValues, uColormap, uValueRange;
// fiber_colors.glsl), part of set_shading_uniforms.
void set_colormap_uniforms(const GlProgram& program, const RenderOptions& options);

// The camera's unit axes, as view.hpp builds them; the camera looks along -back.
struct CameraBasis {
    Vec3f right, up, back;
};
CameraBasis camera_basis(const Camera& camera);

}  // namespace fiblet::viewer
