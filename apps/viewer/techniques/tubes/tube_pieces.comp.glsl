#version 450
// Tube pieces of a decoded batch, one invocation per Hermite segment: nodes
// every uNodeSpacing points of a slot (and its last point), tangents from
// the decoder's unit tangents (tube_spline.hpp), two quadratic Bézier
// pieces per segment, each with its oriented bounding box. With
// uChunksPerBlock > 0 (sorted transparency) the list holds block x
// uChunksPerBlock + chunk and a slot builds only the segments whose first
// node lies in its chunk (points [chunk, chunk + 1) x uChunkSegments):
// segment i of the slot starts at the chunk's i-th node.
layout(local_size_x = 64) in;

#include "scene_buffers.glsl"
#include "tube_piece.glsl"
#include "fiber_radii.glsl"
#include "point_values.glsl"

layout(std430, binding = BINDING_FINE_LIST) readonly buffer FineList { uint fineList[]; };
layout(std430, binding = BINDING_POINTS) readonly buffer Points { vec4 points[]; };
layout(std430, binding = BINDING_TANGENTS) readonly buffer Tangents { vec4 tangents[]; };
layout(std430, binding = BINDING_TUBE_PIECES) writeonly buffer Pieces { TubePiece pieces[]; };

uniform bool uUseList;
uniform uint uFirst;
uniform uint uCount;            // slots in the batch
uniform uint uFirstSlot;        // the run's first slot (runs keep the pieces buffer under the storage limit)
uniform uint uNodeSpacing;      // points between nodes
uniform uint uSegmentsPerSlot;  // tube_segments_per_slot, or tube_segments_per_chunk with chunks
uniform float uTangentScale;    // c of tube_spline.hpp (1/4)
uniform uint uChunksPerBlock;   // 0: slots are whole blocks
uniform uint uChunkSegments;

// The node's unit direction: the mean of the tangents arriving at and
// leaving point k. A block's first point and the point joining the next
// block take the next block's first direction on both sides, so that
// neighbouring slots agree (G¹ across blocks); a fiber's last point (or a
// join to a last block of a single point) its arriving tangent.
vec3 nodeDirection(uint base, uint k, uint last, uint block) {
    vec3 arriving = tangents[base + k].xyz;
    if (k == 0u) return tangents[base + 1u].xyz;
    if (k < last) return normalize(arriving + tangents[base + k + 1u].xyz);
    // The fiber's end, or a join to a last block of one point (no direction).
    if (isLastBlockOfFiber(block) || blockPointCount(block + 1u) < 2u) return arriving;
    vec3 a0, a1;
    blockAnchors(block + 1u, a0, a1);
    vec3 d = a1 - a0;
    return dot(d, d) > 0.0 ? normalize(d) : vec3(1.0, 0.0, 0.0);
}

// Any unit vector perpendicular to unit x.
vec3 perpendicular(vec3 x) {
    vec3 h = abs(x.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    return normalize(cross(x, h));
}

// Range of a quadratic Bézier's coordinate u0, u1, u2 over t in [0, 1].
vec2 quadraticRange(float u0, float u1, float u2) {
    vec2 r = vec2(min(u0, u2), max(u0, u2));
    float den = u0 - 2.0 * u1 + u2;
    if (den != 0.0) {
        float t = (u0 - u1) / den;
        if (t > 0.0 && t < 1.0) {
            float v = (1.0 - t) * (1.0 - t) * u0 + 2.0 * t * (1.0 - t) * u1 + t * t * u2;
            r = vec2(min(r.x, v), max(r.y, v));
        }
    }
    return r;
}

TubePiece makePiece(vec3 p0, vec3 p1, vec3 p2, float r, uint fiber) {
    TubePiece q;
    q.c0 = vec4(p0, r), q.c1 = vec4(p1, r), q.c2 = vec4(p2, r);
    vec3 chord = p2 - p0;
    vec3 x = dot(chord, chord) > 0.0 ? normalize(chord) : (p1 != p0 ? normalize(p1 - p0) : vec3(1.0, 0.0, 0.0));
    vec3 bend = (p1 - p0) - dot(p1 - p0, x) * x;
    vec3 y = dot(bend, bend) > 1e-12 * max(dot(chord, chord), 1e-12) ? normalize(bend) : perpendicular(x);
    vec3 z = cross(x, y);
    // Extent of the curve along each axis, grown by the radius (and a
    // little, so that the box's faces never cut the tube by rounding).
    float grow = r * (1.0 + 1e-3);
    vec3 lo, hi;
    vec3 axes[3] = vec3[3](x, y, z);
    for (int a = 0; a < 3; ++a) {
        vec2 range = quadraticRange(0.0, dot(p1 - p0, axes[a]), dot(p2 - p0, axes[a]));
        lo[a] = range.x - grow, hi[a] = range.y + grow;
    }
    vec3 mid = 0.5 * (lo + hi), halfSize = 0.5 * (hi - lo);
    q.center = vec4(p0 + mid.x * x + mid.y * y + mid.z * z, uintBitsToFloat(fiber));
    q.axisX = vec4(x, halfSize.x), q.axisY = vec4(y, halfSize.y), q.axisZ = vec4(z, halfSize.z);
    return q;
}

// The value at fractional point u of the slot (linear between its points).
float valueAt(uint block, float u) {
    uint k = uint(u);
    float f = u - float(k);
    return f > 0.0 ? mix(pointValue(block, k), pointValue(block, k + 1u), f) : pointValue(block, k);
}

// A piece's values at t = 0, 0.5, 1: points u0..u1 of the slot.
vec4 pieceValues(uint block, float u0, float u1) {
    return vec4(valueAt(block, u0), valueAt(block, 0.5 * (u0 + u1)), valueAt(block, u1), 0.0);
}

void main() {
    uint id = gl_GlobalInvocationID.x;  // piece pair id of this run
    uint slot = uFirstSlot + id / uSegmentsPerSlot, segment = id % uSegmentsPerSlot;
    if (slot >= uCount) return;
    uint entry = uUseList ? fineList[uFirst + slot] : uFirst + slot;
    uint block = uChunksPerBlock > 0u ? entry / uChunksPerBlock : entry;
    uint last = blockSegmentCount(block);  // the slot's points are 0..last
    uint k0 = segment * uNodeSpacing;
    bool otherChunk = false;
    if (uChunksPerBlock > 0u) {
        uint chunkFirst = (entry % uChunksPerBlock) * uChunkSegments;
        k0 += (chunkFirst + uNodeSpacing - 1u) / uNodeSpacing * uNodeSpacing;  // the chunk's first node
        otherChunk = k0 >= chunkFirst + uChunkSegments;
    }
    if (k0 >= last || otherChunk) {
        pieces[2u * id].c0.w = -1.0;
        pieces[2u * id + 1u].c0.w = -1.0;
        return;
    }
    uint k1 = min(k0 + uNodeSpacing, last);
    uint base = slot * (uPointsPerBlock + 1u);
    vec3 n0 = points[base + k0].xyz, n1 = points[base + k1].xyz;
    float len = length(n1 - n0);
    vec3 m0 = len * nodeDirection(base, k0, last, block), m1 = len * nodeDirection(base, k1, last, block);
    vec3 a2 = n0 + uTangentScale * m0, b2 = n1 - uTangentScale * m1, join = 0.5 * (a2 + b2);
    uint fiber = blockFiber[block];
    float radius = fiberRadius(fiber);
    TubePiece first = makePiece(n0, a2, join, radius, fiber), second = makePiece(join, b2, n1, radius, fiber);
    float u0 = float(k0), u1 = float(k1), um = 0.5 * (u0 + u1);
    first.values = pieceValues(block, u0, um);
    second.values = pieceValues(block, um, u1);
    pieces[2u * id] = first;
    pieces[2u * id + 1u] = second;
}
