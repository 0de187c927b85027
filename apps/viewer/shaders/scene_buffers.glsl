// The scene as uploaded: the file's raw blocks (never decoded on the CPU) and
// the small per-block / per-fiber tables built from the fiber LUT.
// Block layout (libfiblet/include/fiblet/fft_format.hpp): bytes 0..11 the two
// anchors as six unorm16 (word k = a | b << 16, most-significant byte first),
// 12..15 the fiber ID (big-endian), 16 flags (low 6 bits: point count),
// 17 index in the fiber, 18.. one direction code per point after the second.

layout(std430, binding = BINDING_BLOCKS) readonly buffer Blocks { uint blockWords[]; };
layout(std430, binding = BINDING_BLOCK_FIBER) readonly buffer BlockFiber { uint blockFiber[]; };

uniform uint uBlockCount;
uniform uint uBlockWords;  // block size / 4
uniform uint uPointsPerBlock;
uniform float uScaling;    // mm per normalized unit
uniform vec3 uOffset;      // mm
uniform float uStep;       // normalized units

uint byteSwap(uint w) {
    return (w >> 24) | ((w >> 8) & 0xff00u) | ((w << 8) & 0xff0000u) | (w << 24);
}

uint blockByte(uint block, uint i) {
    return (blockWords[block * uBlockWords + (i >> 2)] >> ((i & 3u) * 8u)) & 0xffu;
}

// The two anchors in normalized coordinates. The buffer's uint loads are
// little-endian, so a byte swap gives the stored big-endian word a | b << 16.
void blockAnchors(uint block, out vec3 a0, out vec3 a1) {
    uint base = block * uBlockWords;
    uint w0 = byteSwap(blockWords[base]), w1 = byteSwap(blockWords[base + 1u]), w2 = byteSwap(blockWords[base + 2u]);
    a0 = vec3(float(w0 & 0xffffu), float(w0 >> 16), float(w1 & 0xffffu)) / 65535.0;
    a1 = vec3(float(w1 >> 16), float(w2 & 0xffffu), float(w2 >> 16)) / 65535.0;
}

vec3 blockAnchor0(uint block) {
    vec3 a0, a1;
    blockAnchors(block, a0, a1);
    return a0;
}

uint blockFiberId(uint block) { return byteSwap(blockWords[block * uBlockWords + 3u]); }

// Point count from the flags byte (byte 16), validated at upload to 1..pointsPerBlock.
uint blockPointCount(uint block) { return blockWords[block * uBlockWords + 4u] & 0x3fu; }

uint blockCode(uint block, uint k) { return blockByte(block, 18u + k); }

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
