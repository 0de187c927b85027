#version 450
// The voxel ray tracer, one pixel per fragment: the pixel's ray walks the
// grid voxel by voxel (DDA), testing the capsules of each non-empty voxel's
// fragment list analytically and accepting only hits inside that voxel, so
// that the first voxel with a hit holds the nearest one. Opaque: the
// nearest hit, shaded with ambient occlusion (the per-voxel volume,
// trilinear) and a shadow ray towards the light. Transparent
// (uTransparent): every entry into a fiber's tube (a capsule entry on its
// segment's part of the tube, segmentPartOwner), voxel by voxel, the k
// nearest of a voxel insertion-sorted by 32-bit keys (depth in the voxel |
// fragment) and composited front to back with its fiber's alpha
// (fiberAlpha: --opacity, times the fiber's own with --fiber-opacity),
// repeated from the last key when a voxel has more than k.
#include "scene_buffers.glsl"
#include "voxel_segments.glsl"
#include "surface_shading.glsl"

layout(std430, binding = BINDING_VRT_CELLS) readonly buffer Cells { uint cells[]; };
layout(std430, binding = BINDING_VRT_OFFSETS) readonly buffer Offsets { uint offsets[]; };
// The fragment lists: up to 4 buffer textures of uFragmentsPerPart entries.
layout(binding = VRT_FRAGMENT_UNIT) uniform usamplerBuffer uFragments0;
layout(binding = VRT_FRAGMENT_UNIT + 1) uniform usamplerBuffer uFragments1;
layout(binding = VRT_FRAGMENT_UNIT + 2) uniform usamplerBuffer uFragments2;
layout(binding = VRT_FRAGMENT_UNIT + 3) uniform usamplerBuffer uFragments3;
uniform uint uFragmentsPerPart;

uint fragmentAt(uint i) {
    uint part = i / uFragmentsPerPart;
    int j = int(i - part * uFragmentsPerPart);
    switch (part) {
        case 0u: return texelFetch(uFragments0, j).r;
        case 1u: return texelFetch(uFragments1, j).r;
        case 2u: return texelFetch(uFragments2, j).r;
        default: return texelFetch(uFragments3, j).r;
    }
}
layout(std430, binding = BINDING_VRT_VISIBLE) readonly buffer Visible { uint visible[]; };  // voxel_culling.hpp
layout(binding = 1) uniform sampler3D uAmbientOcclusion;

uniform vec3 uCameraRight, uCameraUp, uCameraForward;
uniform float uTanHalfFovY, uAspect;
uniform vec2 uViewportSize;
uniform bool uUseAmbientOcclusion, uUseShadows;
uniform bool uWriteSegments;  // tests: segment + 1 in the fiber buffer instead of fiber + 1
uniform bool uTransparent;  // RenderOptions::transparent(): alphas from fiberAlpha (fiber_colors.glsl)
// Culling (opaque primary rays): skip invisible voxels.
uniform bool uCulling;
uniform bool uEmptySpaceSkipping;  // RenderOptions::empty_space_skipping (empty_space_skipping.glsl)

layout(location = 0) out vec4 outColor;
layout(location = 1) out uint outFiber;

const int kSortedHits = 8;  // k

// The capsule parts an entry point can lie on.
const int kCylinder = 0, kStartSphere = 1, kEndSphere = 2;

// Entry distance of the unit ray t·d into the capsule of radius r around
// ra–rb (-1: none), given in camera-relative coordinates (point − eye, one
// rounding per point, so that capsules sharing a point share it exactly);
// the part of the capsule it lies on, the point relative to ra, and the
// outward normal. Solved from the ray's point nearest the capsule's middle,
// placed with one rounding (fma): neighbouring capsules then see the same
// ray to ~1e-7 of their size, which the tests at their joint need
// (segmentPartOwner); o + along·d rounded in world coordinates moved the ray
// by ~1e-5 mm per capsule.
float capsuleEntry(vec3 d, vec3 ra, vec3 rb, float r, out int part, out vec3 fromA, out vec3 normal) {
    float along = dot(0.5 * (ra + rb), d);
    precise vec3 oa = fma(vec3(along), d, -ra);
    vec3 ba = rb - ra;
    float baba = dot(ba, ba), bard = dot(ba, d), baoa = dot(ba, oa);
    float best = 1e30;
    part = kCylinder;
    normal = vec3(0.0);
    float qa = baba - bard * bard;
    if (qa > 1e-12 * baba) {
        float qb = baba * dot(d, oa) - baoa * bard, qc = baba * dot(oa, oa) - baoa * baoa - r * r * baba;
        float h = qb * qb - qa * qc;
        if (h >= 0.0) {
            float t = (-qb - sqrt(h)) / qa, y = baoa + t * bard;
            if (y > 0.0 && y < baba) best = t, normal = oa + t * d - ba * (y / baba);
        }
    }
    // A cylinder entry between the end planes is the capsule's entry: the
    // spheres' roots there differ from it by less than float precision near
    // the end planes, where deciding by distance would split a joint's
    // surface inconsistently with segmentPartOwner's planes.
    bool onCylinder = best < 1e30;
    for (int end = 0; end < 2 && !onCylinder; ++end) {
        vec3 oc = oa - (end == 0 ? vec3(0.0) : ba);
        float k = dot(d, oc), h = k * k - (dot(oc, oc) - r * r);
        if (h < 0.0) continue;
        float t = -k - sqrt(h);
        if (t < best) best = t, normal = oc + t * d, part = end == 0 ? kStartSphere : kEndSphere;
    }
    if (best >= 1e30) return -1.0;
    fromA = oa + best * d;
    normal = normalize(normal);
    return along + best;
}

struct Walk {
    ivec3 voxel, step;
    vec3 tNext, tDelta;
    float tEnter, tExit, tEnd;
};

// Starts the walk of the ray (o, d) from distance tMin; false when the ray
// misses the grid.
bool startWalk(vec3 o, vec3 d, float tMin, out Walk w) {
    float n = float(uGridN);
    vec3 g = toGrid(o), dg = d / uVoxelMm;
    vec3 inv = vec3(dg.x != 0.0 ? 1.0 / dg.x : 1e30, dg.y != 0.0 ? 1.0 / dg.y : 1e30, dg.z != 0.0 ? 1.0 / dg.z : 1e30);
    vec3 t0 = (vec3(0.0) - g) * inv, t1 = (vec3(n) - g) * inv;
    vec3 tl = min(t0, t1), th = max(t0, t1);
    float tNear = max(max(max(tl.x, tl.y), tl.z), tMin), tFar = min(min(th.x, th.y), th.z);
    if (tFar <= tNear) return false;
    w.voxel = clamp(ivec3(floor(g + tNear * dg)), ivec3(0), ivec3(int(uGridN) - 1));
    w.step = ivec3(sign(dg));
    w.tDelta = abs(inv);
    w.tNext = vec3((vec3(w.voxel) + step(vec3(0.0), dg) - g) * inv);
    if (dg.x == 0.0) w.tNext.x = 1e30;
    if (dg.y == 0.0) w.tNext.y = 1e30;
    if (dg.z == 0.0) w.tNext.z = 1e30;
    w.tEnter = tNear;
    w.tExit = min(min(min(w.tNext.x, w.tNext.y), w.tNext.z), tFar);
    w.tEnd = tFar;
    return true;
}

bool advance(inout Walk w) {
    int axis = w.tNext.x <= w.tNext.y ? (w.tNext.x <= w.tNext.z ? 0 : 2) : (w.tNext.y <= w.tNext.z ? 1 : 2);
    w.voxel[axis] += w.step[axis];
    if (w.voxel[axis] < 0 || w.voxel[axis] >= int(uGridN)) return false;
    w.tEnter = w.tNext[axis];
    w.tNext[axis] += w.tDelta[axis];
    w.tExit = min(min(min(w.tNext.x, w.tNext.y), w.tNext.z), w.tEnd);
    return w.tEnter < w.tEnd;
}

#include "empty_space_skipping.glsl"

struct Hit {
    float t;
    uint segment;
    vec3 normal;
};

void segmentEnds(uint s, out vec3 a, out vec3 b) {
    uint i = segmentFirstPoint(s);
    a = vrtPoint(i), b = vrtPoint(i + 1u);
}

// Whether segment s starts its fiber (else the previous segment ends at its start).
bool firstOfFiber(uint s) {
    uint slot = segmentSlot(s);
    return uAllSegmentsValid || (s == slot * uSegmentsPerSlot && (slot == 0u || blockFiber[slot - 1u] != blockFiber[slot]));
}

// The points before and after segment s in its fiber (has*: whether there is one).
vec3 slotPoint(uint slot, uint k) { return vrtPoint(slot * (uSegmentsPerSlot + 1u) + k); }
void segmentNeighbours(uint s, out bool hasPrev, out vec3 prev, out bool hasNext, out vec3 next) {
    hasPrev = false, hasNext = false, prev = vec3(0.0), next = vec3(0.0);
    if (uAllSegmentsValid) return;
    uint slot = segmentSlot(s), seg = s - slot * uSegmentsPerSlot, count = blockPointCount(slot);
    if (seg > 0u) hasPrev = true, prev = slotPoint(slot, seg - 1u);
    else if (!firstOfFiber(s)) hasPrev = true, prev = slotPoint(slot - 1u, blockPointCount(slot - 1u) - 1u);
    // In this slot (the next block's first point at index count), or the next block's second.
    if (seg + 2u < count || (seg + 2u == count && !isLastBlockOfFiber(slot))) hasNext = true, next = slotPoint(slot, seg + 2u);
    else if (seg + 1u == count && blockSegmentCount(slot + 1u) >= 1u) hasNext = true, next = slotPoint(slot + 1u, 1u);
}

vec3 unitOrZero(vec3 v) { float n = length(v); return n > 0.0 ? v / n : vec3(0.0); }

// Which segment's share of its fiber's tube surface the entry point p
// (relative to a) of segment s's capsule, on the given part, lies on: -1
// the previous segment's, 0 its own, 1 the next one's. The capsules of a
// fiber overlap at joints; this partition (that of Embree's round linear
// curves) gives every point of the tube's surface to one segment. The
// cylinder ends at the planes through the joints normal to the tangent
// there, the sum of the two unit directions (where two equal-radius
// cylinders cross: the part beyond is inside the neighbour); the sphere at
// a joint is the earlier segment's, before the plane where the later one's
// cylinder starts; a fiber's end spheres are its first and last segments'.
// (rp, rn: the neighbouring points, camera-relative.)
int segmentPartOwner(int part, vec3 p, vec3 ra, vec3 rb, bool hasPrev, vec3 rp, bool hasNext, vec3 rn) {
    if (part == kStartSphere) return hasPrev ? -1 : 0;
    vec3 ba = rb - ra, u = unitOrZero(ba), pb = p - ba;
    if (part == kEndSphere) return !hasNext || dot(pb, rn - rb) <= 0.0 ? 0 : 1;
    if (hasPrev && dot(p, unitOrZero(ra - rp) + u) < 0.0) return -1;
    return !hasNext || dot(pb, u + unitOrZero(rn - rb)) <= 0.0 ? 0 : 1;
}

// The entry of the ray (o, d) into segment s's capsule (capsuleEntry).
float segmentCapsuleEntry(vec3 o, vec3 d, uint s, out vec3 ra, out vec3 rb, out int part, out vec3 p, out vec3 normal) {
    vec3 a, b;
    segmentEnds(s, a, b);
    ra = a - o, rb = b - o;
    return capsuleEntry(d, ra, rb, segmentRadiusMm(s), part, p, normal);
}

// segmentPartOwner of segment s's capsule entry.
int entryOwner(vec3 o, uint s, int part, vec3 p, vec3 ra, vec3 rb) {
    if (part == kStartSphere) return firstOfFiber(s) ? 0 : -1;
    bool hasPrev, hasNext;
    vec3 prev, next;
    segmentNeighbours(s, hasPrev, prev, hasNext, next);
    return segmentPartOwner(part, p, ra, rb, hasPrev, prev - o, hasNext, next - o);
}

// The previous (-1) or next (1) segment of s in its fiber.
uint neighbourSegment(uint s, int side) {
    uint slot = segmentSlot(s), seg = s - slot * uSegmentsPerSlot;
    if (side < 0) return seg > 0u ? s - 1u : (slot - 1u) * uSegmentsPerSlot + blockSegmentCount(slot - 1u) - 1u;
    return seg + 1u < blockSegmentCount(slot) ? s + 1u : (slot + 1u) * uSegmentsPerSlot;
}

// The entry of the ray (o, d) into segment s's part of its fiber's tube
// (capsuleEntry, segmentPartOwner) if it lies in [tMin, tMax]; -1
// otherwise. The range first: the neighbours are read only for entries
// that matter.
float segmentEntry(vec3 o, vec3 d, uint s, float tMin, float tMax, out vec3 normal) {
    vec3 ra, rb, p;
    int part;
    float t = segmentCapsuleEntry(o, d, s, ra, rb, part, p, normal);
    if (t < tMin || t > tMax) return -1.0;
    return entryOwner(o, s, part, p, ra, rb) == 0 ? t : -1.0;
}

// The nearest hit beyond tMin (anyHit: the first found, for shadows, which
// ignore culling).
bool traceNearest(vec3 o, vec3 d, float tMin, bool anyHit, out Hit hit) {
    Walk w;
    hit.t = 1e30, hit.segment = 0u, hit.normal = vec3(0.0);
    if (!startWalk(o, d, tMin, w)) return false;
    float eps = 1e-4 * uVoxelMm;
    bool cull = uCulling && !anyHit;
    for (int i = 0; i < 4 * int(uGridN); ++i) {
        if (uEmptySpaceSkipping && !skipEmptySpace(o, d, cull, w)) break;
        uint cell = voxelIndex(w.voxel);
        uint count = cull && visible[cell] == 0u ? 0u : cells[cell] & 0xffffu;
        if (count != 0u) {
            uint first = offsets[cell];
            int part;
            vec3 ra, rb, p;
            for (uint k = first; k < first + count; ++k) {
                uint s = fragmentAt(k);
                vec3 normal, kra, krb, kp;
                int kpart;
                float t = segmentCapsuleEntry(o, d, s, kra, krb, kpart, kp, normal);
                if (t < max(w.tEnter, tMin) - eps || t > w.tExit + eps || t <= tMin) continue;
                if (anyHit) return true;
                // Ties: the lower segment, so that the image does not depend on list order.
                if (t < hit.t || (t == hit.t && s < hit.segment))
                    hit.t = t, hit.segment = s, hit.normal = normal, part = kpart, ra = kra, rb = krb, p = kp;
            }
            if (hit.t < 1e30) {
                // The nearest capsule entry is where the ray enters the tube;
                // the segment owning that point of its surface is this one or
                // a neighbour (whose entry is the same point).
                int owner = entryOwner(o, hit.segment, part, p, ra, rb);
                if (owner != 0) hit.segment = neighbourSegment(hit.segment, owner);
                return true;
            }
        }
        if (!advance(w)) break;
    }
    return false;
}

vec3 shadeHit(vec3 o, vec3 d, Hit h) {
    vec3 a, b;
    segmentEnds(h.segment, a, b);
    uint fiber = blockFiber[segmentSlot(h.segment)];
    if (!uUseAmbientOcclusion && !uUseShadows) return shadeSurface(h.normal, b - a, -d, fiber);
    if (uShowNormals) return 0.5 * h.normal + 0.5;
    vec3 p = o + h.t * d, base = baseColor(b - a, fiber);
    if (!uLighting) return base;
    float ao = 0.0;
    if (uUseAmbientOcclusion)
        ao = texture(uAmbientOcclusion, (toGrid(p) + 0.5 * h.normal) / float(uGridN)).r;
    float lit = 1.0;
    Hit blocker;
    if (uUseShadows && dot(h.normal, uLightDirection) > 0.0 &&
        traceNearest(p + 1e-3 * uVoxelMm * h.normal, uLightDirection, 1e-4 * uVoxelMm, true, blocker))
        lit = 0.0;
    float diffuse = max(dot(h.normal, uLightDirection), 0.0) * lit;
    float specular = pow(max(dot(h.normal, normalize(uLightDirection - d)), 0.0), uShininess) * lit;
    // Ambient occlusion darkens the whole surface (the headlight is near the eye).
    return min((base * (uAmbient + uDiffuse * diffuse) + vec3(uSpecular * specular * highlightShare(fiber))) * (1.0 - ao), vec3(1.0));
}

uint keyOf(float t, Walk w, uint local) {
    float f = clamp((t - w.tEnter) / max(w.tExit - w.tEnter, 1e-30), 0.0, 1.0);
    return (uint(f * 65535.0) << 16) | local;
}

// Composites every capsule the ray enters; returns premultiplied colour and
// coverage, and the nearest hit.
vec4 traceTransparent(vec3 o, vec3 d, out Hit nearest) {
    Walk w;
    nearest.t = 1e30, nearest.segment = 0u, nearest.normal = vec3(0.0);
    vec3 color = vec3(0.0);
    float transmittance = 1.0;
    if (!startWalk(o, d, 0.0, w)) return vec4(0.0);
    for (int i = 0; i < 4 * int(uGridN) && transmittance > 1.0 / 1024.0; ++i) {
        if (uEmptySpaceSkipping && !skipEmptySpace(o, d, false, w)) break;
        uint cell = voxelIndex(w.voxel);
        uint count = min(cells[cell] & 0xffffu, 65535u), first = offsets[cell];
        bool more = count != 0u, started = false;
        uint lastKey = 0u;
        while (more) {
            uint keys[kSortedHits];
            int n = 0;
            for (uint k = 0u; k < count; ++k) {
                vec3 normal;
                float t = segmentEntry(o, d, fragmentAt(first + k), w.tEnter, w.tExit, normal);
                // Each capsule is entered in one voxel: [tEnter, tExit).
                if (t >= w.tExit || t <= 0.0) continue;
                uint key = keyOf(t, w, k);
                if (started && key <= lastKey) continue;
                if (n == kSortedHits && key >= keys[n - 1]) continue;
                int j = min(n, kSortedHits - 1);
                while (j > 0 && keys[j - 1] > key) keys[j] = keys[j - 1], --j;
                keys[j] = key;
                n = min(n + 1, kSortedHits);
            }
            for (int j = 0; j < n; ++j) {
                Hit h;
                h.segment = fragmentAt(first + (keys[j] & 0xffffu));
                vec3 ra, rb, p;
                int part;
                h.t = segmentCapsuleEntry(o, d, h.segment, ra, rb, part, p, h.normal);  // accepted above
                float alpha = fiberAlpha(blockFiber[segmentSlot(h.segment)]);
                if (alpha <= 0.0) continue;  // an invisible fiber: not the pixel's fiber or depth either
                if (h.t < nearest.t) nearest = h;
                color += transmittance * alpha * shadeHit(o, d, h);
                transmittance *= 1.0 - alpha;
            }
            more = n == kSortedHits;
            if (more) lastKey = keys[n - 1], started = true;
        }
        if (!advance(w)) break;
    }
    return vec4(color, 1.0 - transmittance);
}

void main() {
    vec2 ndc = gl_FragCoord.xy / uViewportSize * 2.0 - 1.0;
    vec3 d = normalize(uCameraForward + ndc.x * uTanHalfFovY * uAspect * uCameraRight + ndc.y * uTanHalfFovY * uCameraUp);
    vec3 o = uCameraPosition;
    Hit h;
    if (uTransparent) {
        outColor = traceTransparent(o, d, h);
        if (h.t >= 1e30) discard;
    } else {
        if (!traceNearest(o, d, 0.0, false, h)) discard;
        outColor = vec4(shadeHit(o, d, h), 1.0);
    }
    outFiber = uWriteSegments ? h.segment + 1u : blockFiber[segmentSlot(h.segment)] + 1u;
    gl_FragDepth = windowDepth(o + h.t * d);
}
