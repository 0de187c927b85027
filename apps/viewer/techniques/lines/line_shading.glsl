// What the two line vertex shaders hand to lines.frag.glsl.
uniform mat4 uViewProjection;

layout(location = 0) flat out vec3 vTangent;
layout(location = 1) out vec3 vWorld;
layout(location = 2) flat out uint vFiber;

// Vertex `end` (0 or 1) of the segment p0 -> p1 of fiber `fiber` (index in the file).
void emitSegmentVertex(vec3 p0, vec3 p1, uint end, uint fiber) {
    vec3 d = p1 - p0;
    float len = length(d);
    vTangent = len > 0.0 ? d / len : vec3(0.0);
    vWorld = end == 0u ? p0 : p1;
    vFiber = fiber;
    gl_Position = uViewProjection * vec4(vWorld, 1.0);
}

// A vertex that draws nothing: both ends outside the clip volume.
void emitNothing() {
    vTangent = vec3(0.0);
    vWorld = vec3(0.0);
    vFiber = 0u;
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
}
