#version 450
// Sorted transparency, step 1, after each batch's decode: the depth key of
// every chunk (uChunkSegments consecutive segments) of the batch's blocks,
// from the decoded points: the depth bucket of the chunk's mean point,
// bucket 0 the farthest. Chunks without segments take bucket 0 (drawn first,
// they draw nothing). Keys are stored by block index, not by place in the
// fine list (whose order the culling pass's atomics make vary), so that the
// sort's order does not depend on scheduling; blocks not drawn keep the
// "no key" mark.
layout(local_size_x = 64) in;

#include "scene_buffers.glsl"

layout(std430, binding = BINDING_FINE_LIST) readonly buffer FineList { uint fineList[]; };
layout(std430, binding = BINDING_POINTS) readonly buffer Points { vec4 points[]; };
layout(std430, binding = BINDING_CHUNK_KEYS) writeonly buffer ChunkKeys { uint chunkKeys[]; };

uniform bool uUseList;
uniform uint uFirst;  // the batch's first block in the frame's order
uniform uint uCount;  // blocks in the batch
uniform uint uChunkSegments;
uniform uint uChunksPerBlock;
uniform vec3 uCameraPosition;
uniform vec3 uViewDirection;  // unit, forwards
uniform float uNearDepth;     // depth range of the scene's box along uViewDirection (mm)
uniform float uFarDepth;
uniform uint uBuckets;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uCount * uChunksPerBlock) return;
    uint slot = i / uChunksPerBlock;
    uint first = (i % uChunksPerBlock) * uChunkSegments;
    uint block = uUseList ? fineList[uFirst + slot] : uFirst + slot;
    uint end = min(first + uChunkSegments, blockSegmentCount(block));
    uint key = 0u;
    if (first < end) {
        uint base = slot * (uPointsPerBlock + 1u);
        vec3 sum = vec3(0.0);
        for (uint k = first; k <= end; ++k) sum += points[base + k].xyz;
        float depth = dot(sum / float(end - first + 1u) - uCameraPosition, uViewDirection);
        float farness = (uFarDepth - depth) / max(uFarDepth - uNearDepth, 1e-6);
        key = uint(clamp(farness * float(uBuckets), 0.0, float(uBuckets - 1u)));
    }
    chunkKeys[block * uChunksPerBlock + i % uChunksPerBlock] = key;
}
