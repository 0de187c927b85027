#include "codec/fiber_end_encoder.hpp"

#include <algorithm>
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

double length_keeping_fraction(std::span<const Vec3f> decoded, std::span<const Vec3f> points, double target_length_mm) {
    const std::size_t n = decoded.size();
    const Vec3f prev = decoded[n - 2], last = decoded[n - 1], end = points[n - 1];
    const double seg = std::sqrt(distance2(prev, last));
    const double projected = projected_fraction(prev, last, end);
    if (!(seg > 0) || !(target_length_mm > 0)) return std::clamp(projected, 0.0, 1.0);
    // Where the end may go: as close to the true end as the fiber's other
    // points are to theirs, or as the projection comes.
    double allowed2 = 0, before = 0;
    for (std::size_t k = 0; k + 1 < n; ++k) allowed2 = std::max(allowed2, distance2(decoded[k], points[k]));
    for (std::size_t k = 1; k + 1 < n; ++k) before += std::sqrt(distance2(decoded[k - 1], decoded[k]));
    const double clamped = std::clamp(projected, 0.0, 1.0);
    const Vec3f at_projection = {float(prev.x + clamped * (double(last.x) - prev.x)), float(prev.y + clamped * (double(last.y) - prev.y)),
                                 float(prev.z + clamped * (double(last.z) - prev.z))};
    allowed2 = std::max(allowed2, std::min(distance2(at_projection, end), distance2(last, end)));
    // |prev + f (last - prev) - end|^2 = across^2 + seg^2 (f - projected)^2.
    const double across2 = std::max(0.0, distance2(prev, end) - projected * projected * seg * seg);
    const double reach = std::sqrt(std::max(0.0, allowed2 - across2)) / seg;
    const double lo = std::clamp(projected - reach, 0.0, 1.0), hi = std::clamp(projected + reach, 0.0, 1.0);
    return std::clamp((target_length_mm - before) / seg, lo, hi);
}

std::uint16_t encode_keeping_end(const FiberEncoder& encoder, std::span<const Vec3f> points, bool short_tail,
                                 double step_mm, std::uint32_t fiber_id, std::vector<std::uint8_t>& blocks,
                                 std::vector<Vec3f>& decoded, std::vector<Vec3f>* decoded_exact,
                                 std::vector<Vec3f>& scratch, double target_length_mm) {
    const std::size_t n = points.size();
    const std::uint32_t per_block = encoder.header().points_per_block;
    const std::uint32_t last_block_points = n == 0 ? 0 : std::uint32_t(n - per_block * (encoder.block_count(n) - 1));
    const std::size_t first = decoded.size(), first_exact = decoded_exact ? decoded_exact->size() : 0;
    if (n < 2 || !end_fraction_applies(last_block_points)) {
        encoder.encode(points, fiber_id, blocks, &decoded, decoded_exact);  // the end is an anchor: stored as is
        return kWholeLastStep;
    }
    std::span<const Vec3f> coded = points;
    if (short_tail) {  // the decoder walks whole steps: aim one at the end
        scratch.assign(points.begin(), points.end());
        scratch.back() = step_towards(points[n - 2], points[n - 1], step_mm);
        coded = scratch;
    }
    encoder.encode(coded, fiber_id, blocks, &decoded, decoded_exact);
    Vec3f& last = decoded[first + n - 1];
    const Vec3f prev = decoded[first + n - 2];
    const double f = length_keeping_fraction(std::span<const Vec3f>(decoded).subspan(first, n), points, target_length_mm);
    const std::uint16_t q = quantize_end_fraction(f);
    const Vec3f placed = place_end_point(prev, last, q);
    if (q == kWholeLastStep) return kWholeLastStep;
    last = placed;
    if (decoded_exact && decoded_exact->size() == first_exact + n) {  // an exact decoder places its own end alike
        Vec3f& last_exact = (*decoded_exact)[first_exact + n - 1];
        last_exact = place_end_point((*decoded_exact)[first_exact + n - 2], last_exact, q);
    }
    return q;
}

}  // namespace fiblet::detail
