#version 450
// GPU decoding of fiblets, one workgroup per block, one invocation per point
// (the prefix-product scheme): invocation t takes the local frame of
// direction code t from the table, a log-step (Hillis-Steele) scan in shared
// memory turns these into the running frames L0 L1 ... Lt, and a second scan
// sums the steps into positions. Blocks of more than 64 codes (16-bit files:
// up to 16381) go 64 codes at a time, each chunk starting from the frame and
// point its predecessor ended at; an 8-bit block is one chunk. Points are
// written to slot `slot` of the points buffer: pointsPerBlock + 1 entries,
// the last used by the point that joins the next block of the fiber (its
// first anchor).
layout(local_size_x = 64) in;

#include "scene_buffers.glsl"
#include "decode_common.glsl"

shared mat3 sFrames[64];
shared vec3 sSteps[64];
// 8-bit blocks hold at most 61 codes: one chunk, a loop the compiler can drop.
#if WIDE_BLOCKS
const uint kMaxChunks = (16383u + 63u) / 64u;
#else
const uint kMaxChunks = 1u;
#endif

shared mat3 sChunkFrame;  // the product of a chunk's frames (invocation 63's)
shared vec3 sChunkStep;   // the sum of its steps

void main() {
    uint slot = gl_WorkGroupID.x;
    uint t = gl_LocalInvocationIndex;
    uint block = uUseList ? fineList[uFirst + slot] : uFirst + slot;
    uint n = blockPointCount(block);
    vec3 a0, a1;
    blockAnchors(block, a0, a1);
    mat3 first = frameFromAxis(blockFirstAxis(block, a0, a1));
    uint base = slot * (uPointsPerBlock + 1u);
    if (!uEndsOnly) {
        if (t == 0u) points[base] = vec4(toWorld(a0), 1.0);
        if (t == 1u && n >= 2u) points[base + 1u] = vec4(toWorld(a1), 1.0);
        if (uWriteTangents && t == 0u) tangents[base] = vec4(first[0], 0.0);
        if (uWriteTangents && t == 1u && n >= 2u) tangents[base + 1u] = vec4(first[0], 0.0);
    } else if (n <= 2u && t == 0u) {
        fiberEnds[blockFiber[block]] = vec4(toWorld(n == 1u ? a0 : a1), 1.0);
    }

    // The frame and point the chunk starts from (n is the same for the whole
    // workgroup, so every invocation runs the same chunks and barriers).
    mat3 carryFrame = first;
    vec3 carryPoint = a1;
    vec3 lastPoint = a1;  // invocation 63: the block's last point once it has codes
    uint codes = n > 2u ? n - 2u : 0u;
    for (uint chunk = 0u; chunk < kMaxChunks; ++chunk) {
        uint c0 = chunk * 64u;
        if (c0 >= codes) break;  // the same for the whole workgroup
        uint k = c0 + t;  // point k + 2 turns the frame by the local frame of code k
        bool hasCode = k < codes;
        mat3 running = hasCode ? localFrames[blockCode(block, k)] : mat3(1.0);
        for (uint d = 1u; d < 64u; d <<= 1) {
            sFrames[t] = running;
            barrier();
            if (t >= d) running = sFrames[t - d] * running;
            barrier();
        }
        vec3 offset = hasCode ? uStep * (carryFrame * running[0]) : vec3(0.0);
        vec3 ownStep = offset;
        for (uint d = 1u; d < 64u; d <<= 1) {
            sSteps[t] = offset;
            barrier();
            if (t >= d) offset += sSteps[t - d];
            barrier();
        }
        vec3 p = carryPoint + offset;  // point k + 2
        if (t == 63u) lastPoint = p;   // the chunk's end (never shortened: a join needs a next block)
        // A fiber's last point keeps only a fraction of its step (ENDS chunk).
        if (hasCode && k + 3u == n) p -= (1.0 - keptLastStep(block, n)) * ownStep;
        if (uEndsOnly) {
            if (hasCode && k + 3u == n) fiberEnds[blockFiber[block]] = vec4(toWorld(p), 1.0);
        } else if (hasCode) {
            points[base + k + 2u] = vec4(toWorld(p), 1.0);
            if (uWriteTangents) tangents[base + k + 2u] = vec4(normalize(carryFrame * running[0]), 0.0);
        }
        // Another chunk follows (the same for the whole workgroup): it starts
        // from invocation 63's product and sum. 8-bit blocks never get here.
        if (c0 + 64u < codes) {
            if (t == 63u) sChunkFrame = running, sChunkStep = offset;
            barrier();
            carryFrame = carryFrame * sChunkFrame;
            carryPoint = carryPoint + sChunkStep;
            barrier();  // before the next chunk overwrites them
        }
    }

    if (uEndsOnly || t != 63u || isLastBlockOfFiber(block)) return;
    // The point joining the next block.
    vec3 last = n >= 3u ? lastPoint : n == 2u ? a1 : a0;
    vec3 next = toWorld(blockAnchor0(block + 1u));
    points[base + n] = vec4(next, 1.0);
    if (uWriteTangents) tangents[base + n] = vec4(directionOr(toWorld(last), next, first[0]), 0.0);
}
