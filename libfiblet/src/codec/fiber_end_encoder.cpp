#include "codec/fiber_end_encoder.hpp"

#include <cmath>

#include "fiblet/fiber_ends.hpp"

namespace fiblet::detail {

namespace {

double distance2(Vec3f a, Vec3f b) {
    const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
    return dx * dx + dy * dy + dz * dz;
}

// The point one full step from `from` towards `to`.
Vec3f step_towards(Vec3f from, Vec3f to, double step) {
    const double dx = double(to.x) - from.x, dy = double(to.y) - from.y, dz = double(to.z) - from.z;
    const double s = step / std::sqrt(dx * dx + dy * dy + dz * dz);
    return {float(from.x + s * dx), float(from.y + s * dy), float(from.z + s * dz)};
}

// The fraction of the decoded last segment [a, b] whose end is closest to
// `end` (its projection), clamped to [0, 1].
double projected_fraction(Vec3f a, Vec3f b, Vec3f end) {
    const double ux = double(b.x) - a.x, uy = double(b.y) - a.y, uz = double(b.z) - a.z;
    const double len2 = ux * ux + uy * uy + uz * uz;
    if (!(len2 > 0)) return 1.0;
    return ((double(end.x) - a.x) * ux + (double(end.y) - a.y) * uy + (double(end.z) - a.z) * uz) / len2;
}

}  // namespace

std::uint16_t encode_keeping_end(const FiberEncoder& encoder, std::span<const Vec3f> points, bool short_tail,
                                 double step_mm, std::uint32_t fiber_id, std::vector<std::uint8_t>& blocks,
                                 std::vector<Vec3f>& decoded, std::vector<Vec3f>& scratch) {
    const std::size_t n = points.size();
    const std::uint32_t per_block = encoder.header().points_per_block;
    const std::uint32_t last_block_points = n == 0 ? 0 : std::uint32_t(n - per_block * (encoder.block_count(n) - 1));
    const std::size_t first = decoded.size();
    if (n < 2 || !end_fraction_applies(last_block_points)) {
        encoder.encode(points, fiber_id, blocks, &decoded);  // the end is an anchor: stored as is
        return kWholeLastStep;
    }
    std::span<const Vec3f> coded = points;
    if (short_tail) {  // the decoder walks whole steps: aim one at the end
        scratch.assign(points.begin(), points.end());
        scratch.back() = step_towards(points[n - 2], points[n - 1], step_mm);
        coded = scratch;
    }
    encoder.encode(coded, fiber_id, blocks, &decoded);
    Vec3f& last = decoded[first + n - 1];
    const Vec3f prev = decoded[first + n - 2], end = points[n - 1];
    const std::uint16_t q = quantize_end_fraction(projected_fraction(prev, last, end));
    const Vec3f placed = place_end_point(prev, last, q);
    if (q == kWholeLastStep || distance2(placed, end) >= distance2(last, end)) return kWholeLastStep;
    last = placed;
    return q;
}

}  // namespace fiblet::detail
