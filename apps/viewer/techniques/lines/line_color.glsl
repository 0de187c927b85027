// Illuminated lines (Phong lighting on the tangent, Zöckler et al. 1996):
// a line has no normal, so the diffuse and specular terms use the normal in
// the plane of the tangent and the light (resp. view) direction that
// maximizes them. Colour by direction is |tangent| as RGB (the MRtrix3 /
// TrackVis convention). Shared by lines.frag.glsl and the transparent lines
// (transparency/).
#include "fiber_colors.glsl"

uniform bool uLighting;
uniform vec3 uCameraPosition;
uniform vec3 uLightDirection;  // unit, towards the light
uniform float uAmbient;
uniform float uDiffuse;
uniform float uSpecular;
uniform float uShininess;

vec3 litLineColor(vec3 base, vec3 tangent, vec3 world, uint fiber);

vec3 lineColor(vec3 tangent, vec3 world, uint fiber) { return litLineColor(baseColor(tangent, fiber), tangent, world, fiber); }
// With the point's value (per-point values, fiber_colors.glsl).
vec3 lineColor(vec3 tangent, vec3 world, uint fiber, float value) {
    return litLineColor(baseColor(tangent, fiber, value), tangent, world, fiber);
}

vec3 litLineColor(vec3 base, vec3 tangent, vec3 world, uint fiber) {
    if (!uLighting) return base;
    vec3 view = normalize(uCameraPosition - world);
    float lt = dot(uLightDirection, tangent), vt = dot(view, tangent);
    float diffuse = sqrt(max(1.0 - lt * lt, 0.0));
    float specular = pow(max(diffuse * sqrt(max(1.0 - vt * vt, 0.0)) - lt * vt, 0.0), uShininess);
    return min(base * (uAmbient + uDiffuse * diffuse) + vec3(uSpecular * specular * highlightShare(fiber)), vec3(1.0));
}
