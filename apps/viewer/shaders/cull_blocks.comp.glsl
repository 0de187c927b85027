#version 450
// Per-frame block selection, one invocation per block: fiber subset, frustum
// culling of the block's bounding sphere and the far-view level of detail,
// exactly as fiblet/view.hpp defines them for the CPU. Visible blocks are
// appended to the fine list (decoded in full) or the coarse list (drawn as
// one segment); appends are gathered per workgroup so that each workgroup
// makes one global atomic per list.
layout(local_size_x = 64) in;

#include "scene_buffers.glsl"

layout(std430, binding = BINDING_FIBER_POINTS) readonly buffer FiberPoints { uint fiberPoints[]; };
layout(std430, binding = BINDING_FINE_LIST) writeonly buffer FineList { uint fineList[]; };
layout(std430, binding = BINDING_COARSE_LIST) writeonly buffer CoarseList { uint coarseList[]; };
layout(std430, binding = BINDING_COUNTERS) buffer Counters {
    uint fineBlocks;
    uint coarseBlocks;
    uint fineSegments;
    uint coarseSegments;
};
layout(std430, binding = BINDING_DECISIONS) writeonly buffer Decisions { uint decisions[]; };

uniform bool uFrustumCulling;
uniform vec4 uPlanes[6];  // fiblet::Frustum: n.xyz, d; inside where dot(n, p) + d >= 0
uniform bool uLevelOfDetail;
uniform float uLodPixels;
uniform vec3 uCameraPosition;
uniform vec3 uCameraBack;     // unit, from the target towards the camera
uniform float uTanHalfFovY;
uniform float uViewportHeight;
uniform uvec2 uFiberIdRange;  // inclusive
uniform uvec2 uPointRange;    // inclusive, points per fiber
uniform bool uWriteDecisions;
uniform float uSphereMargin;  // mm the drawing style reaches beyond the centre lines

shared uint sFine, sCoarse, sFineSegments, sCoarseSegments;
shared uint sFineBase, sCoarseBase;

bool sphereIntersectsFrustum(vec4 s) {
    for (int i = 0; i < 6; ++i)
        if (dot(uPlanes[i].xyz, s.xyz) + uPlanes[i].w < -s.w) return false;
    return true;
}

// fiblet::block_is_coarse with fiblet::projected_radius_px.
bool blockIsCoarse(vec4 s) {
    float depth = -dot(uCameraBack, s.xyz - uCameraPosition);
    if (depth <= s.w) return false;  // the sphere reaches the camera plane: infinitely large
    float radiusPx = s.w / (depth * uTanHalfFovY) * 0.5 * uViewportHeight;
    return 2.0 * radiusPx < uLodPixels;
}

void main() {
    uint block = gl_GlobalInvocationID.x;
    uint local = gl_LocalInvocationIndex;
    if (local == 0u) {
        sFine = 0u, sCoarse = 0u, sFineSegments = 0u, sCoarseSegments = 0u;
    }
    barrier();

    uint decision = DECISION_NOT_SELECTED;
    uint segments = 0u;
    if (block < uBlockCount) {
        uint id = blockFiberId(block);
        uint points = fiberPoints[blockFiber[block]];
        if (id >= uFiberIdRange.x && id <= uFiberIdRange.y && points >= uPointRange.x && points <= uPointRange.y) {
            vec4 sphere = blockBoundingSphere(block);
            sphere.w += uSphereMargin;
            if (uFrustumCulling && !sphereIntersectsFrustum(sphere)) {
                decision = DECISION_OUTSIDE_FRUSTUM;
            } else if (uLevelOfDetail && blockIsCoarse(sphere)) {
                decision = DECISION_COARSE;
                // Nothing to draw for a lone point (a one-point fiber).
                segments = isLastBlockOfFiber(block) && blockPointCount(block) < 2u ? 0u : 1u;
            } else {
                decision = DECISION_FINE;
                segments = blockSegmentCount(block);
            }
        }
        if (uWriteDecisions) decisions[block] = decision;
    }

    uint slot = 0u;
    if (segments > 0u) {
        if (decision == DECISION_FINE) {
            slot = atomicAdd(sFine, 1u);
            atomicAdd(sFineSegments, segments);
        } else {
            slot = atomicAdd(sCoarse, 1u);
            atomicAdd(sCoarseSegments, segments);
        }
    }
    barrier();
    if (local == 0u) {
        sFineBase = sFine > 0u ? atomicAdd(fineBlocks, sFine) : 0u;
        sCoarseBase = sCoarse > 0u ? atomicAdd(coarseBlocks, sCoarse) : 0u;
        if (sFineSegments > 0u) atomicAdd(fineSegments, sFineSegments);
        if (sCoarseSegments > 0u) atomicAdd(coarseSegments, sCoarseSegments);
    }
    barrier();
    if (segments > 0u) {
        if (decision == DECISION_FINE)
            fineList[sFineBase + slot] = block;
        else
            coarseList[sCoarseBase + slot] = block;
    }
}
