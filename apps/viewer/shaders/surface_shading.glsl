// What the ray-cast styles (tubes, capsules) share once they have a hit:
// its window depth, and Lambert + Blinn-Phong shading with the headlight
// and colour modes of shading_uniforms.cpp.
#include "fiber_colors.glsl"

uniform mat4 uViewProjection;
uniform bool uLighting;
uniform bool uShowNormals;  // RenderOptions::color_by_normal
uniform vec3 uCameraPosition;
uniform vec3 uLightDirection;  // unit, towards the light
uniform float uAmbient;
uniform float uDiffuse;
uniform float uSpecular;
uniform float uShininess;

// gl_FragDepth of a world point (default depth range).
float windowDepth(vec3 world) {
    vec4 clip = uViewProjection * vec4(world, 1.0);
    return clamp(0.5 * clip.z / clip.w + 0.5, 0.0, 1.0);
}

// Colour of a surface point of fiber `fiber`: unit normal, the fiber's
// tangent there (any length), `toEye` the unit direction towards the camera.
vec3 shadeBase(vec3 base, vec3 normal, vec3 toEye, uint fiber);

vec3 shadeSurface(vec3 normal, vec3 tangent, vec3 toEye, uint fiber) {
    return uShowNormals ? 0.5 * normal + 0.5 : shadeBase(baseColor(tangent, fiber), normal, toEye, fiber);
}
// With the point's value (per-point values, fiber_colors.glsl).
vec3 shadeSurface(vec3 normal, vec3 tangent, vec3 toEye, uint fiber, float value) {
    return uShowNormals ? 0.5 * normal + 0.5 : shadeBase(baseColor(tangent, fiber, value), normal, toEye, fiber);
}

vec3 shadeBase(vec3 base, vec3 normal, vec3 toEye, uint fiber) {
    if (!uLighting) return base;
    float diffuse = max(dot(normal, uLightDirection), 0.0);
    float specular = pow(max(dot(normal, normalize(uLightDirection + toEye)), 0.0), uShininess);
    return min(base * (uAmbient + uDiffuse * diffuse) + vec3(uSpecular * specular * highlightShare(fiber)), vec3(1.0));
}
