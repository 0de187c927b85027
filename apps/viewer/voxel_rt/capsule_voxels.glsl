// Conservative capsule voxelization, the GPU twin of
// capsule_voxelization.hpp (which derives the half-extents): the same float
// operations in the same order (`precise`: no fused multiply-adds), so that
// both visit the same voxels. Calls visitVoxel(ivec3), which the including
// shader declares before including this file and defines after it.

// Capsule a -> b of radius r, voxel units, in a uGridN³ grid.
void forEachCapsuleVoxel(vec3 a, vec3 b, float r) {
    int n = int(uGridN);
    precise vec3 d = b - a;
    precise float len = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    int a0 = 0;
    if (abs(d[1]) > abs(d[a0])) a0 = 1;
    if (abs(d[2]) > abs(d[a0])) a0 = 2;
    int a1 = (a0 + 1) % 3, a2 = (a0 + 2) % 3;
    precise float u0 = 1.0, u1 = 0.0, u2 = 0.0;
    if (len > 0.0) u0 = d[a0] / len, u1 = d[a1] / len, u2 = d[a2] / len;
    precise float e1 = r * sqrt(max(1.0 - u2 * u2, 0.0)) / abs(u0);
    precise float e2 = r * sqrt(max(1.0 - u1 * u1, 0.0)) / abs(u0);
    precise vec3 lo = min(a, b) - r, hi = max(a, b) + r;
    precise float s1 = d[a0] != 0.0 ? d[a1] / d[a0] : 0.0, s2 = d[a0] != 0.0 ? d[a2] / d[a0] : 0.0;
    int iLo = max(int(floor(lo[a0])), 0), iHi = min(int(floor(hi[a0])), n - 1);
    for (int i = iLo; i <= iHi; ++i) {
        precise float x0 = clamp(float(i), lo[a0], hi[a0]), x1 = clamp(float(i + 1), lo[a0], hi[a0]);
        precise float c1a = a[a1] + (x0 - a[a0]) * s1, c1b = a[a1] + (x1 - a[a0]) * s1;
        precise float c2a = a[a2] + (x0 - a[a0]) * s2, c2b = a[a2] + (x1 - a[a0]) * s2;
        precise float l1 = max(min(c1a, c1b) - e1, lo[a1]), h1 = min(max(c1a, c1b) + e1, hi[a1]);
        precise float l2 = max(min(c2a, c2b) - e2, lo[a2]), h2 = min(max(c2a, c2b) + e2, hi[a2]);
        int jLo = max(int(floor(l1)), 0), jHi = min(int(floor(h1)), n - 1);
        int kLo = max(int(floor(l2)), 0), kHi = min(int(floor(h2)), n - 1);
        for (int j = jLo; j <= jHi; ++j)
            for (int k = kLo; k <= kHi; ++k) {
                ivec3 v;
                v[a0] = i, v[a1] = j, v[a2] = k;
                visitVoxel(v);
            }
    }
}
