#version 450
// Sorted transparency, step 2: a stable counting sort, lane by lane. Lane l
// owns the chunk entries [l n, (l + 1) n) (n = ceil(entries / lanes); an
// entry per chunk of every block of the scene, in block order) and counts
// the keyed ones per bucket into histogram[bucket * lanes + l]: no atomics,
// so the order the sort gives never depends on scheduling.
layout(local_size_x = 64) in;

layout(std430, binding = BINDING_CHUNK_KEYS) readonly buffer ChunkKeys { uint chunkKeys[]; };
layout(std430, binding = BINDING_CHUNK_HISTOGRAM) buffer Histogram { uint histogram[]; };

#define NO_KEY 0xffffffffu  // a chunk of a block the frame does not draw

uniform uint uChunks;  // entries: blocks of the scene x chunks per block
uniform uint uLanes;

void main() {
    uint lane = gl_GlobalInvocationID.x;
    if (lane >= uLanes) return;
    uint per = (uChunks + uLanes - 1u) / uLanes;
    uint end = min((lane + 1u) * per, uChunks);
    for (uint i = lane * per; i < end; ++i)
        if (chunkKeys[i] != NO_KEY) histogram[chunkKeys[i] * uLanes + lane] += 1u;
}
