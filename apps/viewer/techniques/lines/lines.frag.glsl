#version 450
// Illuminated lines (Phong lighting on the tangent, Zöckler et al. 1996):
// a line has no normal, so the diffuse and specular terms use the normal in
// the plane of the tangent and the light (resp. view) direction that
// maximizes them. Colour by direction is |tangent| as RGB (the MRtrix3 /
// TrackVis convention). Also writes the fiber index + 1 for picking.
layout(location = 0) flat in vec3 vTangent;
layout(location = 1) in vec3 vWorld;
layout(location = 2) flat in uint vFiber;

#include "fiber_colors.glsl"
#include "occlusion_lookup.glsl"

layout(location = 0) out vec4 outColor;
layout(location = 1) out uint outFiber;

uniform bool uLighting;
uniform vec3 uCameraPosition;
uniform vec3 uLightDirection;  // unit, towards the light
uniform float uAmbient;
uniform float uDiffuse;
uniform float uSpecular;
uniform float uShininess;

void main() {
    vec3 base = baseColor(vTangent, vFiber);
    vec3 color = base;
    if (uLighting) {
        vec3 view = normalize(uCameraPosition - vWorld);
        float lt = dot(uLightDirection, vTangent), vt = dot(view, vTangent);
        float diffuse = sqrt(max(1.0 - lt * lt, 0.0));
        float specular = pow(max(diffuse * sqrt(max(1.0 - vt * vt, 0.0)) - lt * vt, 0.0), uShininess);
        color = base * (uAmbient + uDiffuse * diffuse) + vec3(uSpecular * specular);
    }
    outColor = vec4(min(color, vec3(1.0)) * (1.0 - rasterOcclusion(vWorld, vec3(0.0))), 1.0);
    outFiber = vFiber + 1u;
}
