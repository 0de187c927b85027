// Internal: encoding a streamline so that it ends on its true end point
// (the ENDS chunk, fiblet/fiber_ends.hpp, formats/fft-ends.md).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "fiblet/encode.hpp"

namespace fiblet::detail {

// Encodes `points` (fixed step `step_mm` apart, except the last segment when
// `short_tail`: then the last point is the input's true end, closer than one
// step) and returns the fiber's ENDS value. Where the last point is
// direction-coded, a full step aimed at the true end is encoded instead and
// the fraction of it that reaches the end is returned; where it is an anchor
// (a last block of one or two points) the anchor holds the end itself. Any
// last point is also projected onto its decoded last segment when that comes
// closer. `decoded` receives the points every fiblet decoder produces, the
// placed end included, and `decoded_exact` (when given, and filled by the
// encoder) those of an exact decoder, placed alike; `scratch` is working memory.
// `target_length_mm` (the input's polyline length; 0: unknown) steers the
// end fraction (length_keeping_fraction).
std::uint16_t encode_keeping_end(const FiberEncoder& encoder, std::span<const Vec3f> points, bool short_tail,
                                 double step_mm, std::uint32_t fiber_id, std::vector<std::uint8_t>& blocks,
                                 std::vector<Vec3f>& decoded, std::vector<Vec3f>* decoded_exact,
                                 std::vector<Vec3f>& scratch, double target_length_mm = 0);

// The end fraction for a fiber's decoded points (the last one a whole step
// past the one before) and its targets `points` (the last one the true end):
// the fraction that makes the decoded length `target_length_mm`, as far as
// the end point stays within the larger of the fiber's other point errors
// and the distance the projection of the end leaves; the projection when the
// length is unknown (0). In [0, 1].
double length_keeping_fraction(std::span<const Vec3f> decoded, std::span<const Vec3f> points, double target_length_mm);

}  // namespace fiblet::detail
