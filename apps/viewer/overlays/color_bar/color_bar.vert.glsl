#version 450
// The colour bar's rectangle (window pixels, uBox: x0 y0 x1 y1), a strip.
uniform vec4 uBox;
uniform vec2 uViewport;
layout(location = 0) out vec2 vPixel;

void main() {
    int c = gl_VertexID;
    vPixel = vec2(c & 1, (c >> 1) & 1) * (uBox.zw - uBox.xy) + uBox.xy;
    gl_Position = vec4(vPixel / uViewport * 2.0 - 1.0, 0.0, 1.0);
}
