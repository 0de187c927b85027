#version 450
// Ambient occlusion per voxel: 12 cones around the sphere (the icosahedron's
// vertices; each covers a twelfth of it, half-angle 33.6°) traced through
// the occupancy mip pyramid, each accumulating opacity front to back; the
// voxel's value is their mean. Voxels with no occupied neighbour get 0
// (no surface is shaded there, and the trilinear lookups near surfaces read
// only neighbours of occupied voxels).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(std430, binding = BINDING_VRT_CELLS) readonly buffer Cells { uint cells[]; };
layout(binding = 0) uniform sampler3D uOccupancy;
layout(r16f, binding = 0) writeonly uniform image3D uAmbientOcclusion;
uniform uint uGridN;

#include "cone_occlusion.glsl"

bool nearOccupied(ivec3 v) {
    int n = int(uGridN);
    for (int z = max(v.z - 1, 0); z <= min(v.z + 1, n - 1); ++z)
        for (int y = max(v.y - 1, 0); y <= min(v.y + 1, n - 1); ++y)
            for (int x = max(v.x - 1, 0); x <= min(v.x + 1, n - 1); ++x)
                if ((cells[(uint(z) * uGridN + uint(y)) * uGridN + uint(x)] & 0xffffu) != 0u) return true;
    return false;
}

void main() {
    ivec3 v = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(v, ivec3(uGridN)))) return;
    float ao = nearOccupied(v) ? coneOcclusion(vec3(v) + 0.5) : 0.0;
    imageStore(uAmbientOcclusion, v, vec4(ao));
}
