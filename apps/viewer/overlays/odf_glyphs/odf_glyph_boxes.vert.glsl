#version 450
// One box per glyph: the cube of its bounding radius around its centre
// (box_proxy.glsl), rasterized as the proxy the fragment shader ray casts in.
#include "box_proxy.glsl"

layout(std430, binding = BINDING_GLYPH_CENTERS) readonly buffer GlyphCenters { vec4 glyphCenters[]; };

uniform mat4 uViewProjection;

layout(location = 0) flat out uint vGlyph;
layout(location = 1) out vec3 vWorld;

void main() {
    uint v = uint(gl_VertexID);
    vGlyph = v / kBoxVertices;
    vec4 g = glyphCenters[vGlyph];
    vWorld = boxCorner(v, g.xyz, vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0), vec3(0.0, 0.0, 1.0), vec3(g.w));
    gl_Position = uViewProjection * vec4(vWorld, 1.0);
}
