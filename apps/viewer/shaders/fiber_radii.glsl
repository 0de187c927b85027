// The radius of a fiber's tube or capsules: its own when the scene has
// per-fiber radii and they are on (RenderOptions::fiber_radii), else uRadius.
layout(std430, binding = BINDING_FIBER_RADII) readonly buffer FiberRadii { float fiberRadii[]; };

uniform float uRadius;  // mm
uniform bool uFiberRadii;

float fiberRadius(uint fiber) { return uFiberRadii ? fiberRadii[fiber] : uRadius; }
