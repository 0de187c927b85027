#version 450
// Exact ray–capsule intersection: the capsule (a segment swept by a sphere
// of the fiber's radius) is the union of a cylinder and two end spheres, so the
// ray enters it at the least of their entries (the cylinder's counted only
// between the end planes). Computed from a point near the capsule on the
// ray, for precision. Writes depth, shading and the fiber.
#include "surface_shading.glsl"
#include "slab_clip.glsl"
#include "occlusion_lookup.glsl"

layout(location = 0) flat in vec3 vEnd0;
layout(location = 1) flat in vec3 vEnd1;
layout(location = 2) flat in uint vFiber;
layout(location = 3) in vec3 vWorld;
layout(location = 4) flat in float vRadius;
layout(location = 5) flat in vec2 vValues;

layout(location = 0) out vec4 outColor;
layout(location = 1) out uint outFiber;
layout(depth_greater) out float gl_FragDepth;

// Entry distance of the unit ray (o, d) into the sphere (c, r), or -1.
float sphereEntry(vec3 o, vec3 d, vec3 c, float r) {
    vec3 oc = o - c;
    float b = dot(d, oc), h = b * b - (dot(oc, oc) - r * r);
    return h >= 0.0 ? -b - sqrt(h) : -1.0;
}

void main() {
    vec3 dir = normalize(vWorld - uCameraPosition);
    float along = dot(0.5 * (vEnd0 + vEnd1) - uCameraPosition, dir);
    vec3 o = uCameraPosition + along * dir;  // origin near the capsule
    vec3 a = vEnd0, ba = vEnd1 - vEnd0, oa = o - a;
    float r = vRadius, baba = dot(ba, ba), bard = dot(ba, dir), baoa = dot(ba, oa);
    float best = 1e30;
    vec3 normal = vec3(0.0);
    // The cylinder: |(p - a) x ba|² = r² |ba|², p = o + t d.
    float qa = baba - bard * bard;
    if (qa > 1e-12 * baba) {
        float qb = baba * dot(dir, oa) - baoa * bard, qc = baba * dot(oa, oa) - baoa * baoa - r * r * baba;
        float h = qb * qb - qa * qc;
        if (h >= 0.0) {
            float t = (-qb - sqrt(h)) / qa, y = baoa + t * bard;
            if (y > 0.0 && y < baba) {
                best = t;
                vec3 p = oa + t * dir;
                normal = p - ba * (y / baba);
            }
        }
    }
    for (int end = 0; end < 2; ++end) {
        vec3 c = end == 0 ? vEnd0 : vEnd1;
        float t = sphereEntry(o, dir, c, r);
        if (t != -1.0 && t < best) best = t, normal = o + t * dir - c;
    }
    if (best >= 1e30 || along + best <= 0.0) discard;
    vec3 hit = o + best * dir;
    if (outsideSlab(hit)) discard;
    gl_FragDepth = windowDepth(hit);
    vec3 n = normalize(normal);
    // The value at the hit's projection on the axis (the caps: the ends').
    float s = dot(ba, ba) > 0.0 ? clamp(dot(hit - vEnd0, ba) / dot(ba, ba), 0.0, 1.0) : 0.0;
    outColor = vec4(shadeSurface(n, ba, -dir, vFiber, mix(vValues.x, vValues.y, s)) * (1.0 - rasterOcclusion(hit, n)), fiberAlpha(vFiber));
    outFiber = vFiber + 1u;
}
