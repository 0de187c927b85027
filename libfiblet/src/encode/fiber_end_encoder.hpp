// Internal: encoding a streamline so that it ends on its true end point
// (the ENDS chunk, fiblet/fiber_ends.hpp, formats/fft-ends.md).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "fiblet/encode.hpp"
#include "fiblet/fiber_ends.hpp"

namespace fiblet::detail {

// What a fiber's end placement left, for a second placement with a larger
// allowance (place_end_within).
struct FiberEnd {
    std::uint16_t fraction = kWholeLastStep;  // the ENDS value
    // |decoded - target length| once placed, and the largest error of the
    // fiber's points that the placement does not move (both decoders), mm.
    double length_miss_mm = 0, other_error_mm = 0;
    std::uint32_t last_block_points = 0;
    Vec3f whole_step{}, whole_step_exact{};  // a direction-coded last point before it was placed
};

// Encodes `points` (fixed step `step_mm` apart, except the last segment when
// `short_tail`: then the last point is the input's true end, closer than one
// step) and returns the fiber's ENDS value with what place_end_within needs.
// Where the last point is direction-coded, a full step aimed at the true end
// is encoded instead and the fraction of it that reaches the end is
// returned; where it is an anchor (a last block of one or two points) the
// anchor holds the end itself, rounded to keep the length (8-bit blocks).
// Any last point is also projected onto its
// decoded last segment when that comes closer. `decoded` receives the points
// every fiblet decoder produces, the placed end included, and
// `decoded_exact` (when given, and filled by the encoder) those of an exact
// decoder, placed alike; `scratch` is working memory. `target_length_mm`
// (the input's polyline length; 0: unknown) steers the end fraction
// (length_keeping_fraction) and, where the end is an anchor after codes,
// the rounding of the last block's anchors (round_end_anchors_keeping_length).
// The largest error of decoded[0, m) against points[0, m), over fiblet's
// decode and, when not empty, the exact one (the header's measure), mm.
double largest_error(std::span<const Vec3f> points, std::span<const Vec3f> decoded, std::span<const Vec3f> decoded_exact,
                     std::size_t m);

FiberEnd encode_keeping_end(const FiberEncoder& encoder, std::span<const Vec3f> points, bool short_tail,
                            double step_mm, std::uint32_t fiber_id, std::vector<std::uint8_t>& blocks,
                            std::vector<Vec3f>& decoded, std::vector<Vec3f>* decoded_exact,
                            std::vector<Vec3f>& scratch, double target_length_mm = 0);

// Places the end of a fiber encode_keeping_end encoded again, its moved
// points allowed an error up to `budget_mm` (or what they had, or the
// fiber's other points' error, when larger), both decoders: what a file
// whose recorded max error is at least `budget_mm` can give a fiber whose
// own point errors left its length off. `last_block` is the fiber's last
// block (8-bit layout); `decoded` and `decoded_exact` (empty: not kept) are
// the fiber's points as encode_keeping_end left them, updated alike.
// Returns the ENDS value.
std::uint16_t place_end_within(const FftHeader& h, const FiberEnd& end, std::uint8_t* last_block,
                               std::span<const Vec3f> points, std::span<Vec3f> decoded,
                               std::span<Vec3f> decoded_exact, double target_length_mm, double budget_mm);

// The end fraction for a fiber's decoded points (the last one a whole step
// past the one before) and its targets `points` (the last one the true end):
// the fraction that makes the decoded length `target_length_mm`, as far as
// the end point stays within the larger of the fiber's other point errors,
// the distance the projection of the end leaves and `budget_mm`; the
// projection when the length is unknown (0). In [0, 1].
double length_keeping_fraction(std::span<const Vec3f> decoded, std::span<const Vec3f> points, double target_length_mm,
                               double budget_mm = 0);

// A fiber whose last block holds one or two points ends on anchors, which no
// ENDS fraction moves: where its decoded length misses `target_length_mm` by
// more than its other points' largest error, the last block's anchor words
// are rounded instead to whichever of their neighbours (each value up to
// 3 unorm16 quanta from the written one, as far as the allowance reaches)
// brings the length closest, as far as those anchors stay within the larger of the fiber's
// other point errors, their own and `budget_mm`, for both decoders. `block`
// is the fiber's last block (8-bit layout), holding `block_points` (1 or 2)
// of the fiber's `points`; `decoded` and `decoded_exact` (empty: not kept)
// are updated alike. Returns whether the words changed.
bool round_end_anchors_keeping_length(const FftHeader& h, std::uint8_t* block, std::uint32_t block_points,
                                      std::span<const Vec3f> points, std::span<Vec3f> decoded,
                                      std::span<Vec3f> decoded_exact, double target_length_mm, double budget_mm = 0);

}  // namespace fiblet::detail
