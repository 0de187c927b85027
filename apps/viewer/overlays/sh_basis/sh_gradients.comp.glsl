#version 450
// shValueAndGradient at many directions, read back by the normals' test:
// entries[2i].xyz the direction in, entries[2i + 1] = (∇_S f, f) out.
layout(local_size_x = 64) in;
layout(std430, binding = BINDING_GLYPH_COEFFICIENTS) readonly buffer Coefficients { float coefficients[]; };
layout(std430, binding = BINDING_GLYPH_CENTERS) buffer Entries { vec4 entries[]; };
float shCoefficient(uint i) { return coefficients[i]; }
#include "sh_basis.glsl"

uniform int uLmax;
uniform uint uCount;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uCount) return;
    vec3 gradient;
    float value = shValueAndGradient(0u, uLmax, entries[2u * i].xyz, gradient);
    entries[2u * i + 1u] = vec4(gradient, value);
}
