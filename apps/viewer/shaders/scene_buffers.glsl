// The scene as uploaded: the file's blocks as fiblet's reader holds them in
// memory (never decoded on the CPU) and the small per-block / per-fiber
// tables built from the fiber LUT. Two block layouts, chosen per file:
// programs built for one (WIDE_BLOCKS defined 0 or 1: the decoders, which
// read a code per point) fix it at compile time, the others (which read a
// few fields per block) branch on the uniform uWideBlocks:
// 8-bit blocks (version 2, libfiblet/include/fiblet/fft_format.hpp): bytes
// 0..11 the two anchors as six unorm16 (word k = a | b << 16, most-significant
// byte first), 12..15 the fiber ID (big-endian), 16 flags (low 6 bits: point
// count), 17 index in the fiber, 18.. one direction code per point after the
// second.
// 16-bit blocks (formats/fft16.md; version 17's packed blocks as the reader
// expands them), all little-endian: bytes 0..17 six unorm24 anchor
// coordinates, 18..21 the fiber ID, 22..23 flags (low 14 bits: point count),
// 24.. one u16 code per point after the second.

layout(std430, binding = BINDING_BLOCKS) readonly buffer Blocks { uint blockWords[]; };
layout(std430, binding = BINDING_BLOCK_FIBER) readonly buffer BlockFiber { uint blockFiber[]; };

uniform uint uBlockCount;
uniform uint uBlockWords;  // block size / 4
uniform uint uPointsPerBlock;
uniform float uScaling;    // mm per normalized unit
uniform vec3 uOffset;      // mm
uniform float uStep;       // normalized units
uniform bool uWideBlocks;  // the 16-bit layout, for programs built for both
#ifdef WIDE_BLOCKS
#define WIDE (WIDE_BLOCKS != 0)
#else
#define WIDE uWideBlocks
#endif
// Version 17: the first axis is normalize(q1 - q0) of the anchors' unorm24
// integers (formats/fft16.md), not of the float anchors.
uniform bool uAxisFromAnchorIntegers;

uint byteSwap(uint w) {
    return (w >> 24) | ((w >> 8) & 0xff00u) | ((w << 8) & 0xff0000u) | (w << 24);
}

uint blockByte(uint block, uint i) {
    return (blockWords[block * uBlockWords + (i >> 2)] >> ((i & 3u) * 8u)) & 0xffu;
}

uint blockWord(uint block, uint k) { return blockWords[block * uBlockWords + k]; }

// The six unorm24 anchor coordinates of a 16-bit block (x0 y0 z0 x1 y1 z1).
void blockAnchorIntegers(uint block, out uvec3 q0, out uvec3 q1) {
    uint w0 = blockWord(block, 0u), w1 = blockWord(block, 1u), w2 = blockWord(block, 2u);
    uint w3 = blockWord(block, 3u), w4 = blockWord(block, 4u);
    q0 = uvec3(w0 & 0xffffffu, (w0 >> 24) | ((w1 & 0xffffu) << 8), (w1 >> 16) | ((w2 & 0xffu) << 16));
    q1 = uvec3(w2 >> 8, w3 & 0xffffffu, (w3 >> 24) | ((w4 & 0xffffu) << 8));
}

// The two anchors in normalized coordinates. 8-bit: the buffer's uint loads
// are little-endian, so a byte swap gives the stored big-endian word a | b << 16.
void blockAnchors(uint block, out vec3 a0, out vec3 a1) {
    if (WIDE) {
        uvec3 q0, q1;
        blockAnchorIntegers(block, q0, q1);
        a0 = vec3(q0) / 16777215.0;
        a1 = vec3(q1) / 16777215.0;
        return;
    }
    uint w0 = byteSwap(blockWord(block, 0u)), w1 = byteSwap(blockWord(block, 1u)), w2 = byteSwap(blockWord(block, 2u));
    a0 = vec3(float(w0 & 0xffffu), float(w0 >> 16), float(w1 & 0xffffu)) / 65535.0;
    a1 = vec3(float(w1 >> 16), float(w2 & 0xffffu), float(w2 >> 16)) / 65535.0;
}

vec3 blockAnchor0(uint block) {
    vec3 a0, a1;
    blockAnchors(block, a0, a1);
    return a0;
}

uint blockFiberId(uint block) {
    return WIDE ? (blockWord(block, 4u) >> 16) | (blockWord(block, 5u) << 16) : byteSwap(blockWord(block, 3u));
}

// Point count from the flags, validated at upload to 1..pointsPerBlock.
uint blockPointCount(uint block) {
    return WIDE ? (blockWord(block, 5u) >> 16) & 0x3fffu : blockWord(block, 4u) & 0x3fu;
}

// The direction code of point k + 2.
uint blockCode(uint block, uint k) {
    if (WIDE) return (blockWord(block, 6u + (k >> 1)) >> ((k & 1u) * 16u)) & 0xffffu;
    return blockByte(block, 18u + k);
}

// The first frame's axis (fiblet's block_geometry.hpp / packed_blocks16.hpp):
// normalize(a1 - a0), or for version 17 of the anchors' integer differences
// (exact in a float); coinciding anchors fall back to +x.
vec3 blockFirstAxis(uint block, vec3 a0, vec3 a1) {
    vec3 d = a1 - a0;
    if (WIDE && uAxisFromAnchorIntegers) {
        uvec3 q0, q1;
        blockAnchorIntegers(block, q0, q1);
        d = vec3(ivec3(q1) - ivec3(q0));
    }
    float n2 = dot(d, d);
    return n2 > 0.0 ? (1.0 / sqrt(n2)) * d : vec3(1.0, 0.0, 0.0);
}

// The last block of its fiber, from the LUT (not from the flags, so that a
// bad flag never makes a block reach into the next fiber).
bool isLastBlockOfFiber(uint block) {
    return block + 1u >= uBlockCount || blockFiber[block + 1u] != blockFiber[block];
}

// Segments a block draws in full: its own, plus the one joining its last
// point to the next block's first point.
uint blockSegmentCount(uint block) {
    return blockPointCount(block) - 1u + (isLastBlockOfFiber(block) ? 0u : 1u);
}

// FftHeader::to_world.
vec3 toWorld(vec3 n) { return (n - 0.5) * uScaling - uOffset; }

// fiblet::block_bounding_sphere (view.hpp), the same operations in the same order.
vec4 blockBoundingSphere(uint block) {
    vec3 a0, a1;
    blockAnchors(block, a0, a1);
    vec3 w0 = toWorld(a0), w1 = toWorld(a1);
    uint n = blockPointCount(block);
    if (n < 2u) return vec4(w0, 0.0);
    float r = length(w1 - w0) + float(n - 2u) * uStep * uScaling;
    return vec4(w0, r * (1.0 + 1e-5) + 1e-5 * uScaling);
}
