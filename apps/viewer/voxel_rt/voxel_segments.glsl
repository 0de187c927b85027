// The resident segments of the voxel ray tracer: decoded blocks laid out as
// BlockDecoder's slots (pointsPerBlock + 1 points each), segment s joining
// points s + slot and s + slot + 1 of slot = s / pointsPerBlock; and the
// voxel grid (a cube of uGridN³ voxels of uVoxelMm from uGridOrigin).
// The points lie in up to 8 storage buffers (parts) of uPointsPerPart points
// each (whole slots: a segment's points and its neighbours' share a part).

layout(std430, binding = BINDING_VRT_POINTS) readonly buffer VrtPoints0 { vec4 vrtPoints0[]; };
layout(std430, binding = BINDING_VRT_POINTS1) readonly buffer VrtPoints1 { vec4 vrtPoints1[]; };
layout(std430, binding = BINDING_VRT_POINTS2) readonly buffer VrtPoints2 { vec4 vrtPoints2[]; };
layout(std430, binding = BINDING_VRT_POINTS3) readonly buffer VrtPoints3 { vec4 vrtPoints3[]; };
layout(std430, binding = BINDING_VRT_POINTS4) readonly buffer VrtPoints4 { vec4 vrtPoints4[]; };
layout(std430, binding = BINDING_VRT_POINTS5) readonly buffer VrtPoints5 { vec4 vrtPoints5[]; };
layout(std430, binding = BINDING_VRT_POINTS6) readonly buffer VrtPoints6 { vec4 vrtPoints6[]; };
layout(std430, binding = BINDING_VRT_POINTS7) readonly buffer VrtPoints7 { vec4 vrtPoints7[]; };

uniform uint uGridN;
uniform vec3 uGridOrigin;   // world mm of the grid's corner
uniform float uVoxelMm;
uniform uint uSegmentSlots;     // slots (decoded blocks)
uniform uint uSegmentsPerSlot;  // pointsPerBlock
uniform uint uPointsPerPart;    // points per storage buffer (a multiple of uSegmentsPerSlot + 1)
uniform uint uPointParts;       // storage buffers holding points (1 to 8)
// Every segment of every slot exists (tests: arbitrary capsules, one per
// slot); otherwise the scene's blocks say how many segments each holds.
uniform bool uAllSegmentsValid;
uniform float uRadiusMm;
#include "fiber_radii.glsl"  // uFiberRadii: the scene's per-fiber radii instead of uRadiusMm

// Point i of the slot layout (world mm).
vec3 vrtPoint(uint i) {
    if (uPointParts == 1u) return vrtPoints0[i].xyz;
    uint part = i / uPointsPerPart, j = i - part * uPointsPerPart;
    switch (part) {
        case 0u: return vrtPoints0[j].xyz;
        case 1u: return vrtPoints1[j].xyz;
        case 2u: return vrtPoints2[j].xyz;
        case 3u: return vrtPoints3[j].xyz;
        case 4u: return vrtPoints4[j].xyz;
        case 5u: return vrtPoints5[j].xyz;
        case 6u: return vrtPoints6[j].xyz;
        default: return vrtPoints7[j].xyz;
    }
}

uint segmentSlot(uint s) { return s / uSegmentsPerSlot; }
uint segmentFirstPoint(uint s) { return s + segmentSlot(s); }
// The capsule radius of segment s (mm): its fiber's with per-fiber radii.
float segmentRadiusMm(uint s) {
    return uFiberRadii && !uAllSegmentsValid ? fiberRadii[blockFiber[segmentSlot(s)]] : uRadiusMm;
}
vec3 toGrid(vec3 world) { return (world - uGridOrigin) / uVoxelMm; }
uint voxelIndex(ivec3 v) { return (uint(v.z) * uGridN + uint(v.y)) * uGridN + uint(v.x); }
