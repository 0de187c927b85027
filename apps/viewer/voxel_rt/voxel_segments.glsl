// The resident segments of the voxel ray tracer: decoded blocks laid out as
// BlockDecoder's slots (pointsPerBlock + 1 points each), segment s joining
// points s + slot and s + slot + 1 of slot = s / pointsPerBlock; and the
// voxel grid (a cube of uGridN³ voxels of uVoxelMm from uGridOrigin).

layout(std430, binding = BINDING_VRT_POINTS) readonly buffer VrtPoints { vec4 vrtPoints[]; };

uniform uint uGridN;
uniform vec3 uGridOrigin;   // world mm of the grid's corner
uniform float uVoxelMm;
uniform uint uSegmentSlots;     // slots (decoded blocks)
uniform uint uSegmentsPerSlot;  // pointsPerBlock
// Every segment of every slot exists (tests: arbitrary capsules, one per
// slot); otherwise the scene's blocks say how many segments each holds.
uniform bool uAllSegmentsValid;
uniform float uRadiusMm;

uint segmentSlot(uint s) { return s / uSegmentsPerSlot; }
uint segmentFirstPoint(uint s) { return s + segmentSlot(s); }
vec3 toGrid(vec3 world) { return (world - uGridOrigin) / uVoxelMm; }
uint voxelIndex(ivec3 v) { return (uint(v.z) * uGridN + uint(v.y)) * uGridN + uint(v.x); }
