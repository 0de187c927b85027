// GL's diamond-exit rule for one-pixel lines (OpenGL 4.5, 14.5.1): segment
// a -> b (window coordinates) gives the pixel of centre c a fragment when it
// meets the pixel's diamond |x - c.x| + |y - c.y| < 1/2 and b is not inside
// it. Evaluated here rather than left to the rasterizer so that every driver
// (and the CPU reference of the tests) covers the same pixels: a fiber of
// sub-pixel steps then blends once per pixel it leaves, never twice at a joint.
float diamondDistance(vec2 p, vec2 c) {
    vec2 d = abs(p - c);
    return d.x + d.y;
}

bool exitsDiamond(vec2 a, vec2 b, vec2 c) {
    if (diamondDistance(b, c) < 0.5) return false;
    // The L1 distance along the segment is convex and piecewise linear: its
    // least value is at an end or where the segment crosses c's row or column.
    vec2 d = b - a;
    float least = diamondDistance(a, c);
    if (d.x != 0.0) least = min(least, diamondDistance(a + clamp((c.x - a.x) / d.x, 0.0, 1.0) * d, c));
    if (d.y != 0.0) least = min(least, diamondDistance(a + clamp((c.y - a.y) / d.y, 0.0, 1.0) * d, c));
    return least < 0.5;
}
