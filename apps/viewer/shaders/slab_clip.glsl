// --slab: fibers are drawn only within uSlabHalfWidth mm of the plane
// n·x = d (uSlabPlane = (n, d)), the slice they are read against; a half
// width of 0 turns it off. The fiber fragment shaders discard what lies
// outside (a clip on the GPU; culling is unchanged).
uniform vec4 uSlabPlane;
uniform float uSlabHalfWidth;

bool outsideSlab(vec3 world) {
    return uSlabHalfWidth > 0.0 && abs(dot(uSlabPlane.xyz, world) - uSlabPlane.w) > uSlabHalfWidth;
}
