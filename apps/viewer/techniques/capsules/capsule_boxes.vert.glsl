#version 450
// One capsule per decoded segment (as fine_lines.vert.glsl numbers them):
// the oriented box around it, 36 vertices, outward counter-clockwise;
// segments a block does not have are sent outside the clip volume.
#include "scene_buffers.glsl"

layout(std430, binding = BINDING_FINE_LIST) readonly buffer FineList { uint fineList[]; };
layout(std430, binding = BINDING_POINTS) readonly buffer Points { vec4 points[]; };

uniform mat4 uViewProjection;
uniform bool uUseList;
uniform uint uFirst;
uniform float uRadius;

layout(location = 0) flat out vec3 vEnd0;
layout(location = 1) flat out vec3 vEnd1;
layout(location = 2) flat out uint vFiber;
layout(location = 3) out vec3 vWorld;

// Corners: bit 0 x, bit 1 y, bit 2 z (as tube_boxes.vert.glsl).
const uint kCorners[36] = uint[36](4u, 6u, 2u, 4u, 2u, 0u, 1u, 3u, 7u, 1u, 7u, 5u, 0u, 1u, 5u, 0u, 5u, 4u,
                                   6u, 7u, 3u, 6u, 3u, 2u, 2u, 3u, 1u, 2u, 1u, 0u, 4u, 5u, 7u, 4u, 7u, 6u);

void main() {
    uint v = uint(gl_VertexID);
    uint capsule = v / 36u;
    uint slot = capsule / uPointsPerBlock, segment = capsule % uPointsPerBlock;
    uint block = uUseList ? fineList[uFirst + slot] : uFirst + slot;
    if (segment >= blockSegmentCount(block)) {
        vEnd0 = vEnd1 = vWorld = vec3(0.0);
        vFiber = 0u;
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        return;
    }
    uint base = slot * (uPointsPerBlock + 1u) + segment;
    vec3 a = points[base].xyz, b = points[base + 1u].xyz;
    vEnd0 = a, vEnd1 = b, vFiber = blockFiber[block];
    vec3 axis = b - a;
    float len = length(axis);
    vec3 x = len > 0.0 ? axis / len : vec3(1.0, 0.0, 0.0);
    vec3 y = normalize(cross(x, abs(x.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
    vec3 z = cross(x, y);
    uint c = kCorners[v % 36u];
    vec3 s = vec3(float(c & 1u), float((c >> 1) & 1u), float((c >> 2) & 1u)) * 2.0 - 1.0;
    // Grown a little so that rounding never cuts the capsule.
    float r = uRadius * (1.0 + 1e-3);
    vWorld = 0.5 * (a + b) + s.x * (0.5 * len + r) * x + s.y * r * y + s.z * r * z;
    gl_Position = uViewProjection * vec4(vWorld, 1.0);
}
