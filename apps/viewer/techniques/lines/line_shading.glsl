// What the two line vertex shaders hand to lines.frag.glsl.
uniform mat4 uViewProjection;

layout(location = 0) flat out vec3 vTangent;
layout(location = 1) out vec3 vWorld;
layout(location = 2) flat out uint vFiber;
layout(location = 3) out float vValue;  // the per-point value, interpolated along the segment

// Vertex `end` (0 or 1) of the segment p0 -> p1 of fiber `fiber` (index in
// the file), whose ends' per-point values are v0, v1.
void emitSegmentVertex(vec3 p0, vec3 p1, uint end, uint fiber, float v0, float v1) {
    vValue = end == 0u ? v0 : v1;
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
    vValue = 0.0;
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
}
