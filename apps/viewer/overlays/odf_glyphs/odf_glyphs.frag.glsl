#version 450
// Ray casts the glyph of the box (glyph_ray.glsl) in glyph units, from a
// ray origin near the glyph for precision; writes depth, so that glyphs
// and fibers occlude each other, and colours the surface by |direction| from
// the centre, lit as the fibers' surfaces are.
#include "surface_shading.glsl"

layout(std430, binding = BINDING_GLYPH_COEFFICIENTS) readonly buffer GlyphCoefficients { float glyphCoefficients[]; };
#include "glyph_boxes.glsl"
float shCoefficient(uint i) { return glyphCoefficients[i]; }
#include "sh_basis.glsl"
#include "polynomial_roots.glsl"
#include "glyph_ray.glsl"

uniform uint uCoefficientsPerGlyph;
uniform float uTolerance;  // root finder step, glyph units

layout(location = 0) flat in uint vGlyph;
layout(location = 1) in vec3 vWorld;

layout(location = 0) out vec4 outColor;
layout(location = 1) out uint outFiber;
layout(depth_greater) out float gl_FragDepth;

void main() {
    vec4 g = glyphBoxes[vGlyph].centerRadius;
    vec3 dir = normalize(vWorld - uCameraPosition);
    float along = dot(g.xyz - uCameraPosition, dir);  // camera to the ray's point nearest the centre
    vec3 o = (uCameraPosition + along * dir - g.xyz) / g.w;
    float t;
    vec3 normal;
    if (!traceGlyph(vGlyph * uCoefficientsPerGlyph, o, dir, -along / g.w, uTolerance, t, normal)) discard;
    vec3 local = o + t * dir;
    vec3 hit = g.xyz + g.w * local;
    gl_FragDepth = windowDepth(hit);
    vec3 base = dot(local, local) > 0.0 ? abs(normalize(local)) : vec3(1.0);
    if (uShowNormals) outColor = vec4(0.5 * normal + 0.5, 1.0);
    else if (!uLighting) outColor = vec4(base, 1.0);
    else {
        float diffuse = max(dot(normal, uLightDirection), 0.0);
        float specular = pow(max(dot(normal, normalize(uLightDirection - dir)), 0.0), uShininess);
        outColor = vec4(min(base * (uAmbient + uDiffuse * diffuse) + vec3(uSpecular * specular), vec3(1.0)), 1.0);
    }
    outFiber = 0u;
}
