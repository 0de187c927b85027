#version 450
// One invocation per resident segment: visits the voxels its capsule may
// touch (capsule_voxels.glsl). Pass 0 adds, per voxel, the capsule's
// occupancy and one to its count in a single 32-bit atomic add (count in
// the low 16 bits, occupancy in 1/128 in the high 16); pass 1 writes the
// segment's index into the voxel's fragment list (its place from a cursor
// that the prefix sum of the counts started at the list's first entry).
layout(local_size_x = 64) in;

#include "scene_buffers.glsl"
#include "voxel_segments.glsl"

layout(std430, binding = BINDING_VRT_CELLS) buffer Cells { uint cells[]; };
layout(std430, binding = BINDING_VRT_CURSOR) buffer Cursor { uint cursor[]; };
// The fragment lists in up to 4 parts of uFragmentsPerPart entries
// (voxel_rt_bindings.hpp).
layout(r32ui, binding = 0) uniform writeonly uimageBuffer uFragments0;
layout(r32ui, binding = 1) uniform writeonly uimageBuffer uFragments1;
layout(r32ui, binding = 2) uniform writeonly uimageBuffer uFragments2;
layout(r32ui, binding = 3) uniform writeonly uimageBuffer uFragments3;
uniform uint uFragmentsPerPart;

void writeFragment(uint i, uint segment) {
    uint part = i / uFragmentsPerPart;
    int j = int(i - part * uFragmentsPerPart);
    switch (part) {
        case 0u: imageStore(uFragments0, j, uvec4(segment)); break;
        case 1u: imageStore(uFragments1, j, uvec4(segment)); break;
        case 2u: imageStore(uFragments2, j, uvec4(segment)); break;
        default: imageStore(uFragments3, j, uvec4(segment)); break;
    }
}

uniform uint uPass;
uniform uint uSegmentBase;  // first segment of this dispatch

void visitVoxel(ivec3 v);
#include "capsule_voxels.glsl"

uint gSegment;
vec3 gA, gB;                 // voxel units
vec3 gClipA, gClipB;         // clip plane normals at a and b (zero: a round end)
float gRadius, gEffective;   // radius and the anti-aliasing radius (>= half a voxel)

// Occupancy of the voxel by the capsule: one voxel of soft edge around the
// signed distance at the voxel's centre, the capsule clipped by the planes
// at its joints (consecutive capsules would count their overlap twice);
// thin capsules are widened to half a voxel and scaled down by their width
// (what blocks a ray through a voxel of thin lines is their projected
// width, not their cross-section's area).
float occupancy(ivec3 v) {
    vec3 p = vec3(v) + 0.5, ab = gB - gA;
    if (dot(p - gA, gClipA) < 0.0 || dot(p - gB, gClipB) > 0.0) return 0.0;
    float h = clamp(dot(p - gA, ab) / max(dot(ab, ab), 1e-20), 0.0, 1.0);
    float distance = length(p - gA - h * ab) - gEffective;
    float scale = gRadius / gEffective;
    return clamp(0.5 - distance, 0.0, 1.0) * scale;
}

void visitVoxel(ivec3 v) {
    uint cell = voxelIndex(v);
    if (uPass == 0u) {
        uint occ = uint(occupancy(v) * 128.0 + 0.5);
        atomicAdd(cells[cell], (occ << 16) | 1u);
    } else {
        writeFragment(atomicAdd(cursor[cell], 1u), gSegment);
    }
}

void main() {
    uint s = uSegmentBase + gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
    if (s >= uSegmentSlots * uSegmentsPerSlot) return;
    uint slot = segmentSlot(s), seg = s - slot * uSegmentsPerSlot;
    uint segments = uAllSegmentsValid ? uSegmentsPerSlot : blockSegmentCount(slot);
    if (seg >= segments) return;
    uint i = segmentFirstPoint(s);
    gSegment = s;
    gA = toGrid(vrtPoint(i)), gB = toGrid(vrtPoint(i + 1u));
    gRadius = segmentRadiusMm(s) / uVoxelMm;
    gEffective = max(gRadius, 0.5);
    // Clip planes normal to the central-difference tangents at the joints
    // inside the slot.
    gClipA = vec3(0.0), gClipB = vec3(0.0);
    if (uPass == 0u && !uAllSegmentsValid) {
        if (seg > 0u) gClipA = toGrid(vrtPoint(i + 1u)) - toGrid(vrtPoint(i - 1u));
        if (seg + 1u < segments) gClipB = toGrid(vrtPoint(i + 2u)) - gA;
    }
    forEachCapsuleVoxel(gA, gB, gRadius);
}
