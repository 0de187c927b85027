// Transparent lines, vertex side: each segment is drawn as a screen-space
// box around it, six vertices (two triangles), and the fragment shader keeps
// the pixels of the diamond-exit rule (diamond_exit.glsl).
uniform mat4 uViewProjection;
uniform vec2 uViewportSize;

layout(location = 0) flat out vec3 vTangent;
layout(location = 1) flat out vec3 vWorld;
layout(location = 2) flat out uint vFiber;
layout(location = 3) flat out vec4 vWindowEnds;  // the segment's ends, window pixels
layout(location = 4) flat out vec2 vValues;      // the per-point values at both ends (block_quads.vert.glsl)

vec2 toWindow(vec4 clip) { return (clip.xy / clip.w * 0.5 + 0.5) * uViewportSize; }

// A vertex that draws nothing: outside the clip volume.
void emitNothing() {
    vTangent = vec3(0.0);
    vWorld = vec3(0.0);
    vFiber = 0u;
    vWindowEnds = vec4(0.0);
    vValues = vec2(0.0);
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
}

// Corner `corner` (0..5) of the box of segment p0 -> p1 of fiber `fiber`.
void emitSegmentQuadVertex(vec3 p0, vec3 p1, uint corner, uint fiber) {
    vec4 c0 = uViewProjection * vec4(p0, 1.0), c1 = uViewProjection * vec4(p1, 1.0);
    // Segments reaching behind the near plane are left out (nothing clips them).
    if (c0.z < -c0.w || c1.z < -c1.w) {
        emitNothing();
        return;
    }
    vec2 a = toWindow(c0), b = toWindow(c1);
    // Every pixel whose diamond the segment meets has its centre within 1/2 of
    // the segment's box; 1/32 more is a margin for the rasterizer's snapping
    // of the corners (8 subpixel bits or more).
    vec2 lo = min(a, b) - 0.53125, hi = max(a, b) + 0.53125;
    const vec2 kCorners[6] = vec2[6](vec2(0, 0), vec2(1, 0), vec2(1, 1), vec2(0, 0), vec2(1, 1), vec2(0, 1));
    vec2 w = mix(lo, hi, kCorners[corner]);
    vec3 d = p1 - p0;
    float len = length(d);
    vTangent = len > 0.0 ? d / len : vec3(0.0);
    vWorld = 0.5 * (p0 + p1);
    vFiber = fiber;
    vWindowEnds = vec4(a, b);
    vValues = vec2(0.0);
    gl_Position = vec4(w / uViewportSize * 2.0 - 1.0, 0.0, 1.0);
}
