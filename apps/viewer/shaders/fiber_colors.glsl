// The base colour of a fiber's surface or line: its own colour when the
// scene has per-fiber colours and they are on, else |tangent| as RGB (the
// MRtrix3 / TrackVis convention) or the fixed colour.
layout(std430, binding = BINDING_FIBER_COLORS) readonly buffer FiberColors { vec4 fiberColors[]; };

uniform bool uColorByDirection;
uniform bool uFiberColors;
uniform vec3 uFixedColor;

vec3 baseColor(vec3 tangent, uint fiber) {
    if (uFiberColors) return fiberColors[fiber].rgb;
    return uColorByDirection && dot(tangent, tangent) > 0.0 ? abs(normalize(tangent)) : uFixedColor;
}
