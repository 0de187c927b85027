// Cone-traced occlusion at a point (voxel units) from the occupancy pyramid
// bound as uOccupancy (level 0: uGridN³).
const float kConeTan = 0.6636;        // tan(33.56°): 12 cones of solid angle 4π/12
const float kConeStart = 1.0;         // voxels: beyond the point's own voxel
const float kConeReach = 16.0;        // voxels
const vec3 kConeDirections[12] = vec3[12](
    vec3(0.0, 0.5257, 0.8507), vec3(0.0, -0.5257, 0.8507), vec3(0.0, 0.5257, -0.8507), vec3(0.0, -0.5257, -0.8507),
    vec3(0.5257, 0.8507, 0.0), vec3(-0.5257, 0.8507, 0.0), vec3(0.5257, -0.8507, 0.0), vec3(-0.5257, -0.8507, 0.0),
    vec3(0.8507, 0.0, 0.5257), vec3(-0.8507, 0.0, 0.5257), vec3(0.8507, 0.0, -0.5257), vec3(-0.8507, 0.0, -0.5257));

// A cone's occlusion is the mean of two estimates: opacity accumulated
// front to back (right for occluders at independent depths, but a wall
// half across the cone counts again at every step, so a half-space's
// tangent cones saturate) and the largest coverage seen (right for one
// wall, low for scattered lines). Measured (tests/viewer_voxel_rt_test.cpp):
// a half-space 0.54 (accumulated alone 0.60, largest alone 0.48), and
// correlation 0.92 with Monte-Carlo occlusion rays on a real bundle
// (accumulated alone 0.90 with area-scaled occupancy).
float coneOcclusion(vec3 p) {
    float total = 0.0, n = float(uGridN);
    for (int c = 0; c < 12; ++c) {
        float occluded = 0.0, nearest = 0.0, d = kConeStart;
        while (d < kConeReach) {
            float diameter = max(2.0 * kConeTan * d, 1.0);
            float a = textureLod(uOccupancy, (p + d * kConeDirections[c]) / n, log2(diameter)).r;
            // Steps of half a diameter: opacity of the sample over that length.
            occluded += (1.0 - occluded) * (1.0 - sqrt(max(1.0 - a, 0.0)));
            nearest = max(nearest, a);
            d += 0.5 * diameter;
        }
        total += 0.5 * (occluded + nearest);
    }
    return total / 12.0;
}
