#version 450
// Visibility culling of the voxels (per frame: it depends on the camera).
// Stage 0, once per structure: the eroded occupancy, a voxel "solid" when
// it and its six face neighbours are fully occupied (what no ray crosses
// without a hit, with a voxel of margin). Stage 1: from each occupied
// voxel's centre, march towards the camera; the voxel is visible unless a
// solid voxel lies on the way. Stage 2: level uLevel of the visibility
// pyramid, a voxel visible when any of its eight children is (the trace
// skips invisible blocks of the coarser levels).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(std430, binding = BINDING_VRT_CELLS) readonly buffer Cells { uint cells[]; };
layout(std430, binding = BINDING_VRT_SOLID) buffer Solid { uint solid[]; };
layout(std430, binding = BINDING_VRT_VISIBLE) buffer Visible { uint visible[]; };  // every level, finest first

uniform uint uStage;
uniform uint uGridN;
uniform vec3 uGridOrigin;
uniform float uVoxelMm;
uniform vec3 uCameraPosition;
uniform float uSolidOccupancy;  // summed occupancy that counts as full
uniform uint uLevel, uLevelN, uLevelOffset, uChildOffset;

uint index(ivec3 v, uint n) { return (uint(v.z) * n + uint(v.y)) * n + uint(v.x); }

bool full(ivec3 v) {
    if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, ivec3(uGridN)))) return false;
    return float(cells[index(v, uGridN)] >> 16) / 128.0 >= uSolidOccupancy;
}

void main() {
    ivec3 v = ivec3(gl_GlobalInvocationID);
    if (uStage == 2u) {
        if (any(greaterThanEqual(v, ivec3(uLevelN)))) return;
        uint any = 0u, childN = uLevelN * 2u;
        for (int k = 0; k < 8; ++k) {
            ivec3 c = 2 * v + ivec3(k & 1, (k >> 1) & 1, k >> 2);
            any |= visible[uChildOffset + index(c, childN)];
        }
        visible[uLevelOffset + index(v, uLevelN)] = any;
        return;
    }
    if (any(greaterThanEqual(v, ivec3(uGridN)))) return;
    uint cell = index(v, uGridN);
    if (uStage == 0u) {
        bool s = full(v) && full(v + ivec3(1, 0, 0)) && full(v - ivec3(1, 0, 0)) && full(v + ivec3(0, 1, 0)) &&
                 full(v - ivec3(0, 1, 0)) && full(v + ivec3(0, 0, 1)) && full(v - ivec3(0, 0, 1));
        solid[cell] = s ? 1u : 0u;
        return;
    }
    if ((cells[cell] & 0xffffu) == 0u) {
        visible[cell] = 0u;
        return;
    }
    // Half-voxel steps from two voxels out (the voxel's own neighbourhood
    // never hides it) to the camera or the grid's edge.
    vec3 p = vec3(v) + 0.5, eye = (uCameraPosition - uGridOrigin) / uVoxelMm;
    vec3 d = eye - p;
    float len = length(d);
    d /= max(len, 1e-20);
    uint seen = 1u;
    for (float t = 2.0; t < len; t += 0.5) {
        ivec3 q = ivec3(floor(p + t * d));
        if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, ivec3(uGridN)))) break;
        if (solid[index(q, uGridN)] != 0u) {
            seen = 0u;
            break;
        }
    }
    visible[cell] = seen;
}
