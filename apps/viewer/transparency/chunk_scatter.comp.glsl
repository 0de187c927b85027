#version 450
// Sorted transparency, step 4: each lane walks its chunks in order again and
// puts each at the next place of its (bucket, lane): back to front, and in
// block order within a bucket (stable, deterministic). A sorted place gets
// the chunk's block (what the decoder reads) and its entry, block x chunks
// per block + its index in the block (what the techniques draw from).
layout(local_size_x = 64) in;

layout(std430, binding = BINDING_CHUNK_KEYS) readonly buffer ChunkKeys { uint chunkKeys[]; };
layout(std430, binding = BINDING_CHUNK_HISTOGRAM) buffer Histogram { uint histogram[]; };
layout(std430, binding = BINDING_SORTED_BLOCKS) writeonly buffer SortedBlocks { uint sortedBlocks[]; };
layout(std430, binding = BINDING_SORTED_CHUNKS) writeonly buffer SortedChunks { uint sortedChunks[]; };

#define NO_KEY 0xffffffffu

uniform uint uChunks;
uniform uint uLanes;
uniform uint uChunksPerBlock;

void main() {
    uint lane = gl_GlobalInvocationID.x;
    if (lane >= uLanes) return;
    uint per = (uChunks + uLanes - 1u) / uLanes;
    uint end = min((lane + 1u) * per, uChunks);
    for (uint i = lane * per; i < end; ++i) {
        if (chunkKeys[i] == NO_KEY) continue;
        uint cell = chunkKeys[i] * uLanes + lane;
        uint place = histogram[cell];
        histogram[cell] = place + 1u;
        sortedBlocks[place] = i / uChunksPerBlock;
        sortedChunks[place] = i;
    }
}
