// What both GPU decoders share: the inputs of a decode pass, and the first
// frame of a block, computed as the CPU does (block_geometry.hpp,
// direction_code.hpp).

// The local frames of the file's direction code, frame k's columns (axis
// first, each padded to a vec4): fiblet::DirectionTable's 256 for 8-bit
// blocks (std140 mat3[256]), DirectionTable16's levels^2 (181^2 for version
// 17, 256^2 for version 16: too many for a uniform block) for 16-bit blocks.
// Every code the reader lets through is below the count (it rejects larger
// ones). The decoders are built for one layout (WIDE_BLOCKS).
#if WIDE_BLOCKS
layout(std430, binding = BINDING_WIDE_FRAMES) readonly buffer WideFrames { mat3 localFrames[]; };
#else
layout(std140, binding = BINDING_LOCAL_FRAMES) uniform LocalFrames { mat3 localFrames[256]; };
#endif
layout(std430, binding = BINDING_FINE_LIST) readonly buffer FineList { uint fineList[]; };
layout(std430, binding = BINDING_POINTS) writeonly buffer Points { vec4 points[]; };
// The unit tangent of each point, same layout, when uWriteTangents: the
// direction of the step that arrives at the point (the running frame's first
// column F0), the block's first point taking its first step's direction, the
// point joining the next block the direction towards that block's first point.
layout(std430, binding = BINDING_TANGENTS) writeonly buffer Tangents { vec4 tangents[]; };
layout(std430, binding = BINDING_FIBER_ENDS) writeonly buffer FiberEnds { vec4 fiberEnds[]; };
// Per fiber, the fraction of its last step that is kept (the ENDS chunk,
// formats/fft-ends.md; 1.0 for files without one).
layout(std430, binding = BINDING_FIBER_END_FRACTION) readonly buffer FiberEndFraction { float fiberEndFraction[]; };

uniform bool uUseList;  // blocks fineList[uFirst + slot], else blocks uFirst + slot
uniform uint uFirst;
uniform uint uCount;    // blocks in this pass
uniform bool uEndsOnly; // last blocks of fibers: write only their last point to fiberEnds[fiber]
uniform bool uWriteTangents;

// The unit direction from p to q (mm), or `fallback` when they coincide.
vec3 directionOr(vec3 p, vec3 q, vec3 fallback) {
    vec3 d = q - p;
    float n2 = dot(d, d);
    return n2 > 0.0 ? d * inversesqrt(n2) : fallback;
}

// How much of its last step the last point of a block of n points keeps: the
// fiber's ENDS fraction in its last block when that point is direction-coded
// (n >= 3), else all of it (fiblet::apply_fiber_ends).
float keptLastStep(uint block, uint n) {
    return n >= 3u && isLastBlockOfFiber(block) ? fiberEndFraction[blockFiber[block]] : 1.0;
}

// kFrameHelper of direction_code.hpp.
const vec3 kHelper = vec3(-0.703023156622, 0.039959276793, 0.71004344758);

// fiblet::frame_from_axis.
mat3 frameFromAxis(vec3 axis) {
    vec3 c1 = cross(axis, kHelper);
    if (dot(c1, c1) < 1e-6) c1 = cross(axis, vec3(0.0, kHelper.z, -kHelper.y));
    c1 = normalize(c1);
    vec3 c2 = normalize(cross(axis, c1));
    return mat3(axis, c1, c2);
}
