#version 450
// shValue at many directions, read back by the basis test (the glyphs'
// own GLSL evaluation): directions[i].xyz in, directions[i].w out.
layout(local_size_x = 64) in;
layout(std430, binding = BINDING_GLYPH_COEFFICIENTS) readonly buffer Coefficients { float coefficients[]; };
layout(std430, binding = BINDING_GLYPH_CENTERS) buffer Directions { vec4 directions[]; };
float shCoefficient(uint i) { return coefficients[i]; }
#include "sh_basis.glsl"

uniform int uLmax;
uniform uint uCount;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uCount) return;
    directions[i].w = shValue(0u, uLmax, directions[i].xyz);
}
