#version 450
// Illuminated lines (line_color.glsl); also writes the fiber index + 1 for picking.
layout(location = 0) flat in vec3 vTangent;
layout(location = 1) in vec3 vWorld;
layout(location = 2) flat in uint vFiber;
layout(location = 3) in float vValue;

#include "line_color.glsl"
#include "slab_clip.glsl"
#include "occlusion_lookup.glsl"

layout(location = 0) out vec4 outColor;
layout(location = 1) out uint outFiber;

void main() {
    if (outsideSlab(vWorld)) discard;
    outColor = vec4(min(lineColor(vTangent, vWorld, vFiber, vValue), vec3(1.0)) * (1.0 - rasterOcclusion(vWorld, vec3(0.0))), 1.0);
    outFiber = vFiber + 1u;
}
