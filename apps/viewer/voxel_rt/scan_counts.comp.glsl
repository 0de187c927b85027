#version 450
// Exclusive prefix sum of the voxels' counts (low 16 bits of the cells) into
// the fragment lists' first entries, in chunks of uChunk voxels walked
// sequentially by one invocation each: no barriers (they are what makes
// scans slow on llvmpipe). Stage 0: each chunk's sum; stage 1: one
// invocation scans the chunk sums (and writes the total after them);
// stage 2: each chunk writes its voxels' offsets and fill cursors.
layout(local_size_x = 64) in;

layout(std430, binding = BINDING_VRT_CELLS) readonly buffer Cells { uint cells[]; };
layout(std430, binding = BINDING_VRT_OFFSETS) buffer Offsets { uint offsets[]; };  // voxels + 1
layout(std430, binding = BINDING_VRT_CURSOR) writeonly buffer Cursor { uint cursor[]; };
layout(std430, binding = BINDING_VRT_CHUNKS) buffer Chunks { uint chunks[]; };    // chunk count + 1

uniform uint uStage;
uniform uint uVoxels;
uniform uint uChunk;

void main() {
    uint chunkCount = (uVoxels + uChunk - 1u) / uChunk;
    uint c = gl_GlobalInvocationID.x;
    if (uStage == 1u) {
        if (c != 0u) return;
        uint sum = 0u;
        for (uint i = 0u; i < chunkCount; ++i) {
            uint n = chunks[i];
            chunks[i] = sum;
            sum += n;
        }
        chunks[chunkCount] = sum;
        offsets[uVoxels] = sum;
        return;
    }
    if (c >= chunkCount) return;
    uint first = c * uChunk, last = min(first + uChunk, uVoxels);
    if (uStage == 0u) {
        uint sum = 0u;
        for (uint v = first; v < last; ++v) sum += cells[v] & 0xffffu;
        chunks[c] = sum;
    } else {
        uint sum = chunks[c];
        for (uint v = first; v < last; ++v) {
            offsets[v] = sum, cursor[v] = sum;
            sum += cells[v] & 0xffffu;
        }
    }
}
