#version 450
// Transparent lines: the pixels of the diamond-exit rule, illuminated as
// opaque lines are; alpha is the fiber's opacity (fiberAlpha, blend_target.hpp).
layout(location = 0) flat in vec3 vTangent;
layout(location = 1) flat in vec3 vWorld;
layout(location = 2) flat in uint vFiber;
layout(location = 3) flat in vec4 vWindowEnds;
layout(location = 4) flat in vec2 vValues;

#include "line_color.glsl"
#include "diamond_exit.glsl"
#include "slab_clip.glsl"

layout(location = 0) out vec4 outColor;

void main() {
    if (!exitsDiamond(vWindowEnds.xy, vWindowEnds.zw, gl_FragCoord.xy) || outsideSlab(vWorld)) discard;
    // The value at the pixel's projection on the segment (window space).
    vec2 ab = vWindowEnds.zw - vWindowEnds.xy;
    float s = dot(ab, ab) > 0.0 ? clamp(dot(gl_FragCoord.xy - vWindowEnds.xy, ab) / dot(ab, ab), 0.0, 1.0) : 0.0;
    outColor = vec4(lineColor(vTangent, vWorld, vFiber, mix(vValues.x, vValues.y, s)), fiberAlpha(vFiber));
}
