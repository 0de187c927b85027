// The proxy geometry of the ray-cast styles: an oriented box drawn as 12
// triangles, 36 vertices, outward counter-clockwise (so that back faces
// can be culled).

// Corners: bit 0 x, bit 1 y, bit 2 z (0: -half, 1: +half).
const uint kBoxCorners[36] = uint[36](4u, 6u, 2u, 4u, 2u, 0u, 1u, 3u, 7u, 1u, 7u, 5u, 0u, 1u, 5u, 0u, 5u, 4u,
                                      6u, 7u, 3u, 6u, 3u, 2u, 2u, 3u, 1u, 2u, 1u, 0u, 4u, 5u, 7u, 4u, 7u, 6u);
const uint kBoxVertices = 36u;

// Vertex `v` (mod 36) of the box centred at `centre` with unit axes x, y, z
// (right-handed) and half extents `halfSize`.
vec3 boxCorner(uint v, vec3 centre, vec3 x, vec3 y, vec3 z, vec3 halfSize) {
    uint c = kBoxCorners[v % kBoxVertices];
    vec3 s = vec3(float(c & 1u), float((c >> 1) & 1u), float((c >> 2) & 1u)) * 2.0 - 1.0;
    return centre + s.x * halfSize.x * x + s.y * halfSize.y * y + s.z * halfSize.z * z;
}
