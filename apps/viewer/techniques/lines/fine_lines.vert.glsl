#version 450
// Lines of the decoded blocks, pulled from the points buffer: vertex v draws
// end (v & 1) of segment (v / 2) % pointsPerBlock of slot v / (2 pointsPerBlock);
// segments a block does not have are sent outside the clip volume.
#include "scene_buffers.glsl"
#include "line_shading.glsl"
#include "point_values.glsl"

layout(std430, binding = BINDING_FINE_LIST) readonly buffer FineList { uint fineList[]; };
layout(std430, binding = BINDING_POINTS) readonly buffer Points { vec4 points[]; };

uniform bool uUseList;
uniform uint uFirst;

void main() {
    uint v = uint(gl_VertexID);
    uint slot = v / (2u * uPointsPerBlock);
    uint segment = (v >> 1) % uPointsPerBlock;
    uint block = uUseList ? fineList[uFirst + slot] : uFirst + slot;
    if (segment >= blockSegmentCount(block)) {
        emitNothing();
        return;
    }
    uint base = slot * (uPointsPerBlock + 1u) + segment;
    emitSegmentVertex(points[base].xyz, points[base + 1u].xyz, v & 1u, blockFiber[block], pointValue(block, segment),
                      pointValue(block, segment + 1u));
}
