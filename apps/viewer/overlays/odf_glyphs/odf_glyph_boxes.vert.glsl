#version 450
// One box per glyph around its centre, half sizes its bounding radius times
// its extents (box_proxy.glsl), rasterized as the proxy the fragment shader
// ray casts in.
#include "box_proxy.glsl"
#include "glyph_boxes.glsl"

uniform mat4 uViewProjection;

layout(location = 0) flat out uint vGlyph;
layout(location = 1) out vec3 vWorld;

void main() {
    uint v = uint(gl_VertexID);
    vGlyph = v / kBoxVertices;
    vec4 g = glyphBoxes[vGlyph].centerRadius;
    vec3 halfSize = g.w * glyphBoxes[vGlyph].extents.xyz;
    vWorld = boxCorner(v, g.xyz, vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0), vec3(0.0, 0.0, 1.0), halfSize);
    gl_Position = uViewProjection * vec4(vWorld, 1.0);
}
