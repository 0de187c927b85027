#version 450
// The occupancy volume (level 0 of the mip pyramid that
// glGenerateTextureMipmap then averages): each voxel's summed occupancy
// (high 16 bits of its cell, in 1/128) clamped to one.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(std430, binding = BINDING_VRT_CELLS) readonly buffer Cells { uint cells[]; };
layout(r16f, binding = 0) writeonly uniform image3D uOccupancy;
uniform uint uGridN;

void main() {
    uvec3 v = gl_GlobalInvocationID;
    if (any(greaterThanEqual(v, uvec3(uGridN)))) return;
    uint cell = (v.z * uGridN + v.y) * uGridN + v.x;
    imageStore(uOccupancy, ivec3(v), vec4(min(float(cells[cell] >> 16) / 128.0, 1.0)));
}
