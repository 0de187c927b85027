#version 450
// GPU decoding of fiblets, one workgroup per block, one invocation per point
// (the prefix-product scheme): invocation t takes the local frame of
// direction code t from the LUT, a log-step (Hillis-Steele) scan in shared
// memory turns these into the running frames L0 L1 ... Lt, and a second scan
// sums the steps into positions. Points are written to slot `slot` of the
// points buffer: pointsPerBlock + 1 entries, the last used by the point that
// joins the next block of the fiber (its first anchor).
layout(local_size_x = 64) in;

#include "scene_buffers.glsl"
#include "decode_common.glsl"

shared mat3 sFrames[64];
shared vec3 sSteps[64];

void main() {
    uint slot = gl_WorkGroupID.x;
    uint t = gl_LocalInvocationIndex;
    uint block = uUseList ? fineList[uFirst + slot] : uFirst + slot;
    uint n = blockPointCount(block);
    vec3 a0, a1;
    blockAnchors(block, a0, a1);
    mat3 first = frameFromAxis(anchorAxis(a0, a1));

    // Point t + 2 turns the frame by the local frame of code t.
    bool hasCode = t + 2u < n;
    mat3 running = hasCode ? localFrames[blockCode(block, t)] : mat3(1.0);
    for (uint d = 1u; d < 64u; d <<= 1) {
        sFrames[t] = running;
        barrier();
        if (t >= d) running = sFrames[t - d] * running;
        barrier();
    }
    vec3 offset = hasCode ? uStep * (first * running[0]) : vec3(0.0);
    vec3 ownStep = offset;
    for (uint d = 1u; d < 64u; d <<= 1) {
        sSteps[t] = offset;
        barrier();
        if (t >= d) offset += sSteps[t - d];
        barrier();
    }
    vec3 p = a1 + offset;  // point t + 2
    // A fiber's last point keeps only a fraction of its step (ENDS chunk).
    if (hasCode && t + 3u == n) p -= (1.0 - keptLastStep(block, n)) * ownStep;

    if (uEndsOnly) {
        vec3 last = n == 1u ? a0 : n == 2u ? a1 : p;
        if ((n <= 2u && t == 0u) || (n > 2u && t + 3u == n)) fiberEnds[blockFiber[block]] = vec4(toWorld(last), 1.0);
        return;
    }
    uint base = slot * (uPointsPerBlock + 1u);
    if (t == 0u) points[base] = vec4(toWorld(a0), 1.0);
    if (t == 1u && n >= 2u) points[base + 1u] = vec4(toWorld(a1), 1.0);
    if (hasCode) points[base + t + 2u] = vec4(toWorld(p), 1.0);
    if (t == 63u && !isLastBlockOfFiber(block)) points[base + n] = vec4(toWorld(blockAnchor0(block + 1u)), 1.0);
    if (!uWriteTangents) return;
    if (t == 0u) tangents[base] = vec4(first[0], 0.0);
    if (t == 1u && n >= 2u) tangents[base + 1u] = vec4(first[0], 0.0);
    if (hasCode) tangents[base + t + 2u] = vec4(normalize(first * running[0]), 0.0);
    if (t == 63u && !isLastBlockOfFiber(block)) {
        // Invocation 63 summed every step: p is the block's last point when it has codes.
        vec3 last = n >= 3u ? p : n == 2u ? a1 : a0;
        tangents[base + n] = vec4(directionOr(toWorld(last), toWorld(blockAnchor0(block + 1u)), first[0]), 0.0);
    }
}
