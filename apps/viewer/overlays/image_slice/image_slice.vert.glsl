#version 450
// The slice's quad: corners (0,0), (1,0), (0,1), (1,1) of the grid, a strip.
uniform vec3 uCorners[4];
uniform mat4 uViewProjection;
layout(location = 0) out vec2 vTexel;

void main() {
    int c = gl_VertexID;
    vTexel = vec2(float(c & 1), float((c >> 1) & 1));
    gl_Position = uViewProjection * vec4(uCorners[c], 1.0);
}
