// The base colour of a fiber's surface or line: its own colour when the
// scene has per-fiber colours and they are on, else |tangent| as RGB (the
// MRtrix3 / TrackVis convention) or the fixed colour. The buffer's alpha is
// the fiber's own opacity (GpuScene::set_fiber_opacities; 1 without).
layout(std430, binding = BINDING_FIBER_COLORS) readonly buffer FiberColors { vec4 fiberColors[]; };

uniform bool uColorByDirection;
uniform bool uFiberColors;
uniform vec3 uFixedColor;
uniform float uGlobalOpacity = 1.0;  // RenderOptions::opacity
uniform bool uFiberOpacity = false;  // RenderOptions::fiber_opacity

// Highlighted fibers (picked; RenderOptions::highlighted_fibers, sorted):
// when there are any, every other fiber is drawn dimmed and greyed.
const int kMaxHighlighted = 64;  // kMaxHighlightedFibers
uniform int uHighlightedCount = 0;
uniform uint uHighlighted[kMaxHighlighted];

bool highlighted(uint fiber) {
    int lo = 0, hi = uHighlightedCount;  // binary search of [lo, hi)
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (uHighlighted[mid] < fiber) lo = mid + 1;
        else hi = mid;
    }
    return lo < uHighlightedCount && uHighlighted[lo] == fiber;
}

// Per-point values through a colour map (scene/colormaps.hpp: the same
// anchors, interpolated the same way) over uValueRange, clamped.
const int kColormapAnchors = 17;
uniform bool uPointValues = false;
uniform vec3 uColormap[kColormapAnchors];
uniform vec2 uValueRange = vec2(0.0, 1.0);

vec3 colormapColor(float value) {
    float t = uValueRange.y > uValueRange.x ? clamp((value - uValueRange.x) / (uValueRange.y - uValueRange.x), 0.0, 1.0) : 0.5;
    float x = t * float(kColormapAnchors - 1);
    int i = min(int(x), kColormapAnchors - 2);
    float f = x - float(i);
    return uColormap[i] * (1.0 - f) + uColormap[i + 1] * f;
}

vec3 ownColor(vec3 tangent, uint fiber) {
    if (uFiberColors) return fiberColors[fiber].rgb;
    return uColorByDirection && dot(tangent, tangent) > 0.0 ? abs(normalize(tangent)) : uFixedColor;
}

// The colour of a point whose value is `value` (what the line shaders
// interpolate): the colour map's when the per-point values are on.
vec3 ownColor(vec3 tangent, uint fiber, float value) {
    return uPointValues ? colormapColor(value) : ownColor(tangent, fiber);
}

// How much of its light a fiber gets: all, or a dimmed fiber 30 %.
float highlightShare(uint fiber) { return uHighlightedCount == 0 || highlighted(fiber) ? 1.0 : 0.3; }

vec3 dimmed(vec3 c, uint fiber) {
    float share = highlightShare(fiber);
    return share == 1.0 ? c : share * mix(vec3(dot(c, vec3(0.299, 0.587, 0.114))), c, 0.25);
}

vec3 baseColor(vec3 tangent, uint fiber) { return dimmed(ownColor(tangent, fiber), fiber); }
vec3 baseColor(vec3 tangent, uint fiber, float value) { return dimmed(ownColor(tangent, fiber, value), fiber); }

// What a fragment of the fiber blends with (blend_target.hpp): the global
// opacity, times the fiber's own when they are on; 1 in opaque frames.
float fiberAlpha(uint fiber) { return uFiberOpacity ? uGlobalOpacity * fiberColors[fiber].a : uGlobalOpacity; }
