#version 450
// GPU decoding, one invocation per block: the frames multiplied one after the
// other, as the scalar reference decoder does, with 64 blocks side by side
// in a workgroup (the CPU's "SIMD lanes per fiblet" layout). Same inputs and
// outputs as decode_blocks.comp.glsl. No barriers, which is what a software
// rasterizer such as llvmpipe wants: it runs a workgroup's barriers as
// coroutine switches.
layout(local_size_x = 64) in;

#include "scene_buffers.glsl"
#include "decode_common.glsl"

void main() {
    uint slot = gl_GlobalInvocationID.x;
    if (slot >= uCount) return;
    uint block = uUseList ? fineList[uFirst + slot] : uFirst + slot;
    uint n = blockPointCount(block);
    vec3 a0, a1;
    blockAnchors(block, a0, a1);
    mat3 frame = frameFromAxis(blockFirstAxis(block, a0, a1));
    vec3 p = n == 1u ? a0 : a1;
    uint base = slot * (uPointsPerBlock + 1u);
    vec3 tangent = frame[0];
    if (!uEndsOnly) {
        points[base] = vec4(toWorld(a0), 1.0);
        if (n >= 2u) points[base + 1u] = vec4(toWorld(a1), 1.0);
        if (uWriteTangents) {
            tangents[base] = vec4(tangent, 0.0);
            if (n >= 2u) tangents[base + 1u] = vec4(tangent, 0.0);
        }
    }
    for (uint k = 2u; k < n; ++k) {
        frame = frame * localFrames[blockCode(block, k - 2u)];
        vec3 stepVec = uStep * frame[0];
        p += stepVec;
        // A fiber's last point keeps only a fraction of its step (ENDS chunk).
        if (k + 1u == n) p -= (1.0 - keptLastStep(block, n)) * stepVec;
        if (!uEndsOnly) points[base + k] = vec4(toWorld(p), 1.0);
        if (!uEndsOnly && uWriteTangents) tangents[base + k] = vec4(normalize(frame[0]), 0.0);
        tangent = frame[0];
    }
    if (uEndsOnly)
        fiberEnds[blockFiber[block]] = vec4(toWorld(p), 1.0);
    else if (!isLastBlockOfFiber(block)) {
        vec3 next = toWorld(blockAnchor0(block + 1u));
        points[base + n] = vec4(next, 1.0);
        if (uWriteTangents) tangents[base + n] = vec4(directionOr(toWorld(p), next, normalize(tangent)), 0.0);
    }
}
