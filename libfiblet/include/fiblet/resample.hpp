// fiblet — fixed-step resampling of variable-step streamlines.
#pragma once

#include <span>
#include <vector>

#include "fiblet/geometry.hpp"

namespace fiblet {

// Where a resampled point lies on its input polyline: on segment
// [segment, segment + 1], at fraction t of it.
struct PolylinePosition {
    std::size_t segment;
    double t;
};

// Walks along the polyline from its first point and emits points on it whose
// consecutive straight-line distances all equal `step` (the codec's model of
// a streamline: a fixed chord length). The tail shorter than one step is
// dropped (at most `step` of length). Points are appended to `out` (cleared
// first). A streamline shorter than one step keeps only its first point.
// With `positions`, also says where each output point lies on the input.
void resample_fixed_step(std::span<const Vec3f> in, double step, std::vector<Vec3f>& out,
                         std::vector<PolylinePosition>* positions = nullptr);

// A dropped tail shorter than this fraction of the step is not kept
// (0.1 µm at a 0.1 mm step: far below the codec's error).
inline constexpr double kKeptTailFraction = 1e-3;

// The points the codec aims at for a resampled streamline: those of
// resample_fixed_step, then the input's last point itself when the dropped
// tail is longer than kKeptTailFraction of the step (straight-line distance),
// so the streamline ends where its input does (formats/fft-ends.md).
// Returns whether that end point was appended (the last segment is then
// shorter than the step).
bool resample_keeping_end(std::span<const Vec3f> in, double step, std::vector<Vec3f>& out,
                          std::vector<PolylinePosition>* positions = nullptr);

// Per-point values (`components` floats per input point) at resampled points:
// linear interpolation between the two input points of the segment each
// lies on, i.e. linear in arc length along the input polyline.
void interpolate_point_values(std::span<const PolylinePosition> positions, const float* in_values,
                              std::size_t components, float* out_values);

// Distance from a point to a polyline (a single point is a degenerate
// polyline), in the units of the inputs: the exact minimum over all segments.
double distance_to_polyline(Vec3f p, std::span<const Vec3f> polyline);

// Same, searching only the segments [hint - window, hint + window] and
// moving `hint` to the closest one: linear time for points visited in order
// along the polyline (as decoded points of a resampled streamline are).
double distance_to_polyline_near(Vec3f p, std::span<const Vec3f> polyline, std::size_t& hint,
                                 std::size_t window = 16);

}  // namespace fiblet
