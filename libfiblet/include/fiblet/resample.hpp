// fiblet — fixed-step resampling of variable-step streamlines.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "fiblet/geometry.hpp"

namespace fiblet {

// The curve through a variable-step streamline's points that resampling
// places its points on (stored in the RSMP chunk, formats/fft.md §5).
enum class ResampleCurve : std::uint32_t {
    // The input polyline itself. Chords between points off its vertices cut
    // every corner: iFOD2 streamlines came out 0.4 % shorter. Files whose RSMP
    // chunk has no curve field were resampled so.
    polyline = 0,
    // A C¹ cubic (Hermite, Bessel tangents) through the input points: on a
    // smooth curve sampled at any spacing, chords of the step keep the input
    // polyline's length on average (iFOD2: within 0.1 mm, 0.2 step, per
    // fiber; not within the codec's error).
    cubic = 1,
    // The same cubic with its tangents scaled by a tension fitted fiber by
    // fiber (length_keeping_tension) so that the resampled streamline, end
    // point kept, is as long as the input polyline. Segments of 4 steps and
    // more are straight, so no tension reaches the length of a fiber whose
    // segments are long against the step and turn (chords cut their corners).
    cubic_keeping_length = 2,
    // Curve 2 with rounded corners instead: a segment longer than
    // 2 kCornerSteps steps is straight but for a Hermite piece of
    // kCornerSteps steps at each end, from the tangent at its point to the
    // segment's direction; shorter segments get the whole cubic. The
    // tension rounds every corner, so it reaches the length at any step.
    // What compress writes.
    rounded_keeping_length = 3,
};

// Steps of chord length over which a long segment turns from its ends'
// tangents to its own direction (rounded_keeping_length).
inline constexpr double kCornerSteps = 2.0;

// Whether a curve's tension is fitted per fiber to keep the length.
inline constexpr bool keeps_length(ResampleCurve c) {
    return c == ResampleCurve::cubic_keeping_length || c == ResampleCurve::rounded_keeping_length;
}

// Tensions the fit tries: 0 (the polyline) to this (rounder than Bessel's).
inline constexpr double kMaxResampleTension = 4.0;
// The fit stops when the lengths agree within this fraction of the step
// (0.5 µm at 0.5 mm: far below the codec's error) or after this many
// regula falsi steps.
inline constexpr double kLengthTolerance = 1e-3;
inline constexpr int kMaxTensionIterations = 16;
// Fitted tensions are multiples of this: 16 bits hold every one.
inline constexpr double kTensionQuantum = 1.0 / 8192;
static_assert(kMaxResampleTension / kTensionQuantum < 65536);

// The tension in [0, kMaxResampleTension] of the cubic through `in` whose
// resampling at `step` (end point kept), stretched by `stretch`, has the
// input polyline's length; or the closest one tried
// when no tension reaches it (fibers whose corners are much shorter than
// the step: its chords cut them whatever the curve). `stretch` is the
// decoder's (decoder_stretch): its steps are that much longer than the
// chords they follow, the lateral zig-zag of the direction codes taking up
// the difference. Deterministic: compress and stats find the same tension.
double length_keeping_tension(std::span<const Vec3f> in, double step, double stretch = 1,
                              ResampleCurve curve = ResampleCurve::rounded_keeping_length);

// How much longer the decoder's step (header step × scaling, in float as
// the header holds them) is than the resampling step: what compress and
// stats pass to length_keeping_tension.
inline double decoder_stretch(float header_step, float scaling, double resample_step_mm) {
    return double(header_step) * double(scaling) / resample_step_mm;
}


// Where a resampled point lies along its input: on input segment
// [segment, segment + 1], at parameter t of it (its fraction of the segment
// on the polyline, the Hermite parameter on the cubic).
struct PolylinePosition {
    std::size_t segment;
    double t;
};

// How a file's variable-step input was resampled (its RSMP chunk, and the
// decoder's stretch of the step from its header: decoder_stretch).
struct Resampling {
    double step_mm = 0;
    ResampleCurve curve = ResampleCurve::cubic;
    double stretch = 1;  // what the length-keeping tension allowed for (cubic_keeping_length)
};

// Walks along the curve from the first point and emits points on it whose
// consecutive straight-line distances all equal `step` (the codec's model of
// a streamline: a fixed chord length). The tail shorter than one step is
// dropped (at most `step` of length). Points are appended to `out` (cleared
// first). A streamline shorter than one step keeps only its first point.
// With `positions`, also says where each output point lies on the input.
void resample_fixed_step(std::span<const Vec3f> in, double step, std::vector<Vec3f>& out,
                         ResampleCurve curve = ResampleCurve::rounded_keeping_length,
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
                          ResampleCurve curve = ResampleCurve::rounded_keeping_length,
                         std::vector<PolylinePosition>* positions = nullptr);

// resample_keeping_end on a length-keeping curve whose tension is already
// known (length_keeping_tension's).
bool resample_cubic_keeping_end(std::span<const Vec3f> in, double step, double tension, std::vector<Vec3f>& out,
                                std::vector<PolylinePosition>* positions = nullptr,
                                ResampleCurve curve = ResampleCurve::rounded_keeping_length);

// The same, resampled as a file says (curve, step and, for the
// length-keeping tension, the decoder's stretch): the points compress aimed
// at, so that a comparison with the source measures what the codec did.
void resample_fixed_step(std::span<const Vec3f> in, const Resampling& how, std::vector<Vec3f>& out);
bool resample_keeping_end(std::span<const Vec3f> in, const Resampling& how, std::vector<Vec3f>& out);

// Per-point values (`components` floats per input point) at resampled points:
// linear interpolation between the two input points of the segment each
// lies on, by the position's parameter.
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
