#version 450
// Transparent lines of decoded blocks: vertex v draws corner v % 6 of local
// segment (v / 6) % uSlotSegments of slot v / (6 uSlotSegments). A slot is a
// whole block (unsorted) or one chunk of uSlotSegments segments of it
// (sorted, uChunksPerBlock > 0: the list holds block x uChunksPerBlock + chunk).
#include "scene_buffers.glsl"
#include "segment_quads.glsl"
#include "point_values.glsl"

layout(std430, binding = BINDING_FINE_LIST) readonly buffer FineList { uint fineList[]; };
layout(std430, binding = BINDING_POINTS) readonly buffer Points { vec4 points[]; };

uniform bool uUseList;
uniform uint uFirst;
uniform uint uSlotSegments;
uniform uint uChunksPerBlock;  // 0: slots are whole blocks

void main() {
    uint v = uint(gl_VertexID);
    uint slot = v / (6u * uSlotSegments);
    uint entry = uUseList ? fineList[uFirst + slot] : uFirst + slot;
    uint block = uChunksPerBlock > 0u ? entry / uChunksPerBlock : entry;
    uint segment = (v / 6u) % uSlotSegments + (uChunksPerBlock > 0u ? (entry % uChunksPerBlock) * uSlotSegments : 0u);
    if (segment >= blockSegmentCount(block)) {
        emitNothing();
        return;
    }
    uint base = slot * (uPointsPerBlock + 1u) + segment;
    emitSegmentQuadVertex(points[base].xyz, points[base + 1u].xyz, v % 6u, blockFiber[block]);
    vValues = vec2(pointValue(block, segment), pointValue(block, segment + 1u));
}
