// The tube model shared by the tube shaders and their tests: a sphere of
// radius r swept along a C¹ curve through nodes every `s` decoded points,
// each cubic Hermite segment drawn as two quadratic Bézier pieces.
//
// Hermite segment from node P0 (tangent m0) to node P1 (tangent m1), both
// tangents of length |P1 - P0| along the nodes' unit directions. Its two
// quadratic pieces are (P0, P0 + c m0, J) and (J, P1 - c m1, P1) with
// J = (P0 + c m0 + P1 - c m1) / 2 and c = kBezierTangentScale = 1/4:
// a quadratic piece spanning half of the cubic's parameter has end
// derivative 2 (a2 - a1) per piece parameter = 4 c m per cubic parameter,
// which is m only for c = 1/4; then J is also exactly the cubic's midpoint
// (P0 + P1) / 2 + (m0 - m1) / 8. The paper's text says 1/3 (tests check both).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "scene/gpu_scene.hpp"
#include "fiblet_viewer/render_options.hpp"

namespace fiblet::viewer {

inline constexpr float kBezierTangentScale = 0.25f;  // also in tube_pieces.comp.glsl

// Decoded steps between two nodes for tubes of `radius_mm` on a file of
// `step_mm` steps: about four radii (rounded), 1 to 20 steps. Tubes hide
// deviations well under their radius, and at four radii a piece's box is
// about as long as it is wide, so boxes neither overlap much (the overdraw
// of one box per point at 0.1 mm steps) nor bulge on bends. At 0.25 mm
// this is 10 steps (1 mm) at 0.1 mm steps, which keeps the curve within
// 3 µm (p99) of the points on SD_STREAM data.
inline std::uint32_t tube_node_spacing(float radius_mm, float step_mm) {
    if (!(step_mm > 0) || !(radius_mm > 0)) return 1;
    const float s = std::round(4.0f * radius_mm / step_mm);
    return std::uint32_t(std::clamp(s, 1.0f, 20.0f));
}

// The largest radius drawn (what culling spheres grow by), and the
// smallest (what the node spacing follows, so that no tube is drawn with
// nodes farther apart than its radius asks).
inline float tube_radius_reach(const GpuScene& scene, const RenderOptions& o) {
    return o.fiber_radii && scene.has_fiber_radii() ? scene.max_fiber_radius() : o.tube_radius_mm;
}
inline float tube_radius_for_spacing(const GpuScene& scene, const RenderOptions& o) {
    return o.fiber_radii && scene.has_fiber_radii() ? scene.min_fiber_radius() : o.tube_radius_mm;
}

// Hermite segments (two pieces each) of a points-buffer slot of up to
// points_per_block + 1 points at spacing s: slots reserve this many.
inline std::uint32_t tube_segments_per_slot(std::uint32_t points_per_block, std::uint32_t s) {
    return (points_per_block + s - 1) / s;
}
// Hermite segments starting in a chunk of `chunk_segments` points (sorted
// transparency): the nodes, multiples of s, among them. Building only these
// keeps the pieces of a batch of chunks proportional to the chunks, not to
// chunks x block length (16-bit files: 26 chunks of blocks of 254 points).
inline std::uint32_t tube_segments_per_chunk(std::uint32_t chunk_segments, std::uint32_t s) {
    return (chunk_segments + s - 1) / s;
}

}  // namespace fiblet::viewer
