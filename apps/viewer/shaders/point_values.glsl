// Per-point values (GpuScene::set_point_values) beside the blocks: point k
// of block b in slot b * pointsPerBlock + k. Needs scene_buffers.glsl.
layout(std430, binding = BINDING_POINT_VALUES) readonly buffer PointValues { float pointValues[]; };

uniform bool uPointValues = false;

// The value of point k of `block`; k == its point count: the next block's
// first point (the segment joining them).
float pointValue(uint block, uint k) {
    if (!uPointValues) return 0.0;
    return k < blockPointCount(block) ? pointValues[block * uPointsPerBlock + k] : pointValues[(block + 1u) * uPointsPerBlock];
}
