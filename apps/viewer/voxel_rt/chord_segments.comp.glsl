#version 450
// One chord per block, straight from the raw blocks (nothing decoded): its
// first point to the next block's first point, or for a fiber's last block
// to the fiber's last point (the coarse level of detail's segment,
// coarse_lines.vert.glsl). Slot b of the output holds chord b's two ends.
layout(local_size_x = 64) in;

#include "scene_buffers.glsl"

layout(std430, binding = BINDING_FIBER_ENDS) readonly buffer FiberEnds { vec4 fiberEnds[]; };
layout(std430, binding = BINDING_VRT_POINTS) writeonly buffer Chords { vec4 chords[]; };

void main() {
    uint block = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
    if (block >= uBlockCount) return;
    vec3 p0 = toWorld(blockAnchor0(block));
    vec3 p1 = isLastBlockOfFiber(block) ? fiberEnds[blockFiber[block]].xyz : toWorld(blockAnchor0(block + 1u));
    chords[2u * block] = vec4(p0, 1.0);
    chords[2u * block + 1u] = vec4(p1, 1.0);
}
