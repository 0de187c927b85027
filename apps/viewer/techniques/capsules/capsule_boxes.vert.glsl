#version 450
// One capsule per decoded segment (as fine_lines.vert.glsl numbers them):
// the oriented box around it (box_proxy.glsl); segments a block does not
// have are sent outside the clip volume. A slot draws uSlotSegments
// segments: its whole block, or with uChunksPerBlock > 0 (sorted
// transparency) one chunk, the list holding block x uChunksPerBlock + chunk.
#include "scene_buffers.glsl"
#include "box_proxy.glsl"
#include "fiber_radii.glsl"
#include "point_values.glsl"

layout(std430, binding = BINDING_FINE_LIST) readonly buffer FineList { uint fineList[]; };
layout(std430, binding = BINDING_POINTS) readonly buffer Points { vec4 points[]; };

uniform mat4 uViewProjection;
uniform bool uUseList;
uniform uint uFirst;
uniform uint uSlotSegments;    // uPointsPerBlock, or a chunk's segments
uniform uint uChunksPerBlock;  // 0: slots are whole blocks

layout(location = 0) flat out vec3 vEnd0;
layout(location = 1) flat out vec3 vEnd1;
layout(location = 2) flat out uint vFiber;
layout(location = 3) out vec3 vWorld;
layout(location = 4) flat out float vRadius;
layout(location = 5) flat out vec2 vValues;  // the per-point values at both ends

void main() {
    uint v = uint(gl_VertexID);
    uint capsule = v / kBoxVertices;
    uint slot = capsule / uSlotSegments, segment = capsule % uSlotSegments;
    uint entry = uUseList ? fineList[uFirst + slot] : uFirst + slot;
    uint block = entry;
    if (uChunksPerBlock > 0u) {
        block = entry / uChunksPerBlock;
        segment += (entry % uChunksPerBlock) * uSlotSegments;
    }
    if (segment >= blockSegmentCount(block)) {
        vEnd0 = vEnd1 = vWorld = vec3(0.0);
        vFiber = 0u;
        vRadius = 0.0;
        vValues = vec2(0.0);
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        return;
    }
    uint base = slot * (uPointsPerBlock + 1u) + segment;
    vec3 a = points[base].xyz, b = points[base + 1u].xyz;
    vEnd0 = a, vEnd1 = b, vFiber = blockFiber[block];
    vValues = vec2(pointValue(block, segment), pointValue(block, segment + 1u));
    vec3 axis = b - a;
    float len = length(axis);
    vec3 x = len > 0.0 ? axis / len : vec3(1.0, 0.0, 0.0);
    vec3 y = normalize(cross(x, abs(x.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
    vec3 z = cross(x, y);
    // Grown a little so that rounding never cuts the capsule.
    vRadius = fiberRadius(vFiber);
    float r = vRadius * (1.0 + 1e-3);
    vWorld = boxCorner(v, 0.5 * (a + b), x, y, z, vec3(0.5 * len + r, r, r));
    gl_Position = uViewProjection * vec4(vWorld, 1.0);
}
