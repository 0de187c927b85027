#version 450
// Level of detail: a coarse block is one segment from its first point to the
// next block's first point (or, for the last block of a fiber, to the fiber's
// last point, decoded once on the GPU when the scene was loaded). Read from
// the raw blocks: nothing is decoded per frame.
#include "scene_buffers.glsl"
#include "line_shading.glsl"
#include "point_values.glsl"

layout(std430, binding = BINDING_COARSE_LIST) readonly buffer CoarseList { uint coarseList[]; };
layout(std430, binding = BINDING_FIBER_ENDS) readonly buffer FiberEnds { vec4 fiberEnds[]; };

void main() {
    uint v = uint(gl_VertexID);
    uint block = coarseList[v >> 1];
    uint fiber = blockFiber[block];
    vec3 p0 = toWorld(blockAnchor0(block));
    vec3 p1 = isLastBlockOfFiber(block) ? fiberEnds[fiber].xyz : toWorld(blockAnchor0(block + 1u));
    float v1 = isLastBlockOfFiber(block) ? pointValue(block, blockPointCount(block) - 1u) : pointValue(block + 1u, 0u);
    emitSegmentVertex(p0, p1, v & 1u, fiber, pointValue(block, 0u), v1);
}
