// Hierarchical empty-space skipping (the paper's traversal of the mip
// pyramid), between the voxels the trace's DDA tests: where the walk's
// voxel is empty, the ray climbs the pyramid while the parent cell is empty
// too, leaves the coarsest empty cell through its exit face in one step,
// and goes on at that level with the cell it enters there: down a level
// while the cell holds something, up again while a parent is empty. The DDA
// resumes in the first voxel that holds something, in the state it would
// have reached there itself, so the image does not change.
// The pyramids (voxel_pyramid.hpp): the culling's visibility for opaque
// primary rays (what the eye cannot see is empty to them), in `visible`;
// the structure's occupancy for every other ray, whose level 0 is the
// cells' counts and levels 1.. in uOccupiedPyramid.
// Needs (trace.frag.glsl): cells, visible, Walk, toGrid, uGridN, uVoxelMm.

layout(binding = VRT_OCCUPIED_UNIT) uniform usamplerBuffer uOccupiedPyramid;
uniform int uPyramidLevels;
uniform uint uPyramidOffset[VRT_PYRAMID_LEVELS];  // per level, in cells from the finest

bool cellEmpty(ivec3 cell, int level, bool visibleOnly) {
    uint n = uGridN >> uint(level);
    uint i = (uint(cell.z) * n + uint(cell.y)) * n + uint(cell.x);
    if (visibleOnly) return visible[uPyramidOffset[level] + i] == 0u;
    if (level == 0) return (cells[i] & 0xffffu) == 0u;
    return texelFetch(uOccupiedPyramid, int(uPyramidOffset[level] - uPyramidOffset[1] + i)).r == 0u;
}

// Moves the walk into the voxel where the ray enters the next cell of
// `level` past the one holding the walk's voxel, with the DDA's state there
// (as startWalk computes it). false when the ray leaves the grid first.
bool leaveCell(vec3 o, vec3 d, int level, inout Walk w) {
    vec3 g = toGrid(o), dg = d / uVoxelMm;
    vec3 inv = vec3(dg.x != 0.0 ? 1.0 / dg.x : 1e30, dg.y != 0.0 ? 1.0 / dg.y : 1e30, dg.z != 0.0 ? 1.0 / dg.z : 1e30);
    bvec3 still = equal(dg, vec3(0.0));
    int size = 1 << level;
    ivec3 lo = (w.voxel >> level) << level;
    vec3 t = mix((vec3(lo) + step(vec3(0.0), dg) * float(size) - g) * inv, vec3(1e30), still);
    int axis = t.x <= t.y ? (t.x <= t.z ? 0 : 2) : (t.y <= t.z ? 1 : 2);
    float tLeave = t[axis];
    if (tLeave >= w.tEnd) return false;
    // Across the exit face on its axis; on the others where the ray is then
    // (within the cell: the ray leaves it through that face).
    ivec3 v = clamp(ivec3(floor(g + tLeave * dg)), lo, lo + size - 1);
    v[axis] = w.step[axis] > 0 ? lo[axis] + size : lo[axis] - 1;
    if (v[axis] < 0 || v[axis] >= int(uGridN)) return false;
    w.voxel = v;
    w.tEnter = max(tLeave, w.tEnter);
    w.tNext = mix((vec3(v) + step(vec3(0.0), dg) - g) * inv, vec3(1e30), still);
    w.tExit = min(min(min(w.tNext.x, w.tNext.y), w.tNext.z), w.tEnd);
    return true;
}

// Moves the walk past the empty space from its voxel on, to the first voxel
// that holds something (visibleOnly: something visible); false when the
// ray leaves the grid first.
bool skipEmptySpace(vec3 o, vec3 d, bool visibleOnly, inout Walk w) {
    int level = 0;
    for (int i = 0; i < 8 * int(uGridN); ++i) {
        if (!cellEmpty(w.voxel >> level, level, visibleOnly)) {
            if (level == 0) return true;
            --level;  // something in this cell: look closer
            continue;
        }
        while (level + 1 < uPyramidLevels && cellEmpty(w.voxel >> (level + 1), level + 1, visibleOnly)) ++level;
        if (!leaveCell(o, d, level, w)) return false;
    }
    return true;  // out of steps: the DDA goes on voxel by voxel from here
}
