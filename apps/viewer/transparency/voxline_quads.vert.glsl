#version 450
// Voxlines: the segments of one voxel in one of its precomputed axis orders
// (forwards, or backwards for the negative axis); vertex v draws corner
// v % 6 of the order's segment v / 6.
#include "segment_quads.glsl"

// Two vec4 per segment: p0 (w: the fiber's index, as bits) and p1, world mm.
layout(std430, binding = BINDING_VOXLINE_SEGMENTS) readonly buffer Segments { vec4 segmentEnds[]; };
layout(std430, binding = BINDING_VOXLINE_ORDERS) readonly buffer Orders { uint orders[]; };

uniform uint uOrderFirst;
uniform uint uOrderCount;
uniform bool uReverse;

void main() {
    uint v = uint(gl_VertexID);
    uint i = v / 6u;
    uint s = orders[uOrderFirst + (uReverse ? uOrderCount - 1u - i : i)];
    vec4 p0 = segmentEnds[2u * s], p1 = segmentEnds[2u * s + 1u];
    emitSegmentQuadVertex(p0.xyz, p1.xyz, v % 6u, floatBitsToUint(p0.w));
}
