#version 450
// The occupancy pyramid of the trace's empty-space skipping
// (voxel_pyramid.hpp, empty_space_skipping.glsl): a cell of level uLevel is
// 1 when any of its eight children holds something, level 1 from the cells'
// counts (level 0 itself, not stored), the next ones from the level before.
// Levels 1.. lie in one R8UI buffer, finest first.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(std430, binding = BINDING_VRT_CELLS) readonly buffer Cells { uint cells[]; };
layout(r8ui, binding = 0) uniform uimageBuffer uPyramid;

uniform uint uGridN;
uniform uint uLevel;                     // 1..
uniform uint uLevelOffset, uChildOffset;  // in the buffer (uChildOffset: level uLevel - 1, from level 2)

void main() {
    uint n = uGridN >> uLevel, childN = 2u * n;
    uvec3 v = gl_GlobalInvocationID;
    if (any(greaterThanEqual(v, uvec3(n)))) return;
    uint occupied = 0u;
    for (int k = 0; k < 8; ++k) {
        uvec3 c = 2u * v + uvec3(k & 1, (k >> 1) & 1, k >> 2);
        uint i = (c.z * childN + c.y) * childN + c.x;
        occupied |= uLevel == 1u ? uint((cells[i] & 0xffffu) != 0u) : imageLoad(uPyramid, int(uChildOffset + i)).r;
    }
    imageStore(uPyramid, int(uLevelOffset + (v.z * n + v.y) * n + v.x), uvec4(occupied));
}
