#version 450
// Grey = the voxel's value windowed to [min, max] of the slice.
uniform sampler2D uSlice;
uniform vec2 uWindow;
layout(location = 0) in vec2 vTexel;
layout(location = 0) out vec4 outColor;
layout(location = 1) out uint outFiber;

void main() {
    float v = texture(uSlice, vTexel).r;
    float grey = clamp((v - uWindow.x) / (uWindow.y - uWindow.x), 0.0, 1.0);
    outColor = vec4(vec3(grey), 1.0);
    outFiber = 0u;
}
