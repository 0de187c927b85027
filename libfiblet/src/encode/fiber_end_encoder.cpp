#include "encode/fiber_end_encoder.hpp"

#include <algorithm>
#include <array>
#include <vector>
#include <cmath>

#include "core/vec_math.hpp"
#include "fiblet/fft_format.hpp"
#include "fiblet/geometry_error.hpp"
#include "fiblet/fiber_ends.hpp"

namespace fiblet::detail {

namespace {

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

// How many unorm16 quanta an end anchor's value may move from the written
// one, at most (up to 7^3 candidates an anchor).
constexpr int kEndAnchorReach = 3;


// An anchor's world point for fiblet's float decoders and for an exact
// decoder (rounded to float, as compress keeps the exact decode).
Vec3f float_anchor(const FftHeader& h, const std::uint16_t* q) {
    return h.to_world(unpack_unorm16(q[0]), unpack_unorm16(q[1]), unpack_unorm16(q[2]));
}
Vec3f exact_anchor(const FftHeader& h, const std::uint16_t* q) {
    auto one = [&](int i) { return float((double(q[i]) / 65535.0 - 0.5) * double(h.scaling) - double(h.offset[i])); };
    return {one(0), one(1), one(2)};
}

// Version 2 anchor word k holds the pair (q[2k], q[2k + 1]) as a | b << 16,
// most-significant byte first (BlockView::anchor_words reads it).
void put_anchor_words(std::uint8_t* block, const std::array<std::uint16_t, 6>& q) {
    for (int k = 0; k < 3; ++k) {
        std::uint8_t* w = block + 4 * k;
        w[0] = std::uint8_t(q[2 * k + 1] >> 8), w[1] = std::uint8_t(q[2 * k + 1]);
        w[2] = std::uint8_t(q[2 * k] >> 8), w[3] = std::uint8_t(q[2 * k]);
    }
}

}  // namespace

double length_keeping_fraction(std::span<const Vec3f> decoded, std::span<const Vec3f> points, double target_length_mm,
                               double budget_mm) {
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
    allowed2 = std::max({allowed2, std::min(distance2(at_projection, end), distance2(last, end)), budget_mm * budget_mm});
    // |prev + f (last - prev) - end|^2 = across^2 + seg^2 (f - projected)^2.
    const double across2 = std::max(0.0, distance2(prev, end) - projected * projected * seg * seg);
    const double reach = std::sqrt(std::max(0.0, allowed2 - across2)) / seg;
    const double lo = std::clamp(projected - reach, 0.0, 1.0), hi = std::clamp(projected + reach, 0.0, 1.0);
    return std::clamp((target_length_mm - before) / seg, lo, hi);
}

bool round_end_anchors_keeping_length(const FftHeader& h, std::uint8_t* block, std::uint32_t block_points,
                                      std::span<const Vec3f> points, std::span<Vec3f> decoded,
                                      std::span<Vec3f> decoded_exact, double target_length_mm, double budget_mm) {
    const std::size_t n = points.size(), i0 = n - block_points;
    const bool exact = !decoded_exact.empty();
    if (!(target_length_mm > 0) || block_points < 1 || block_points > 2 || i0 < 1 || decoded.size() != n ||
        (exact && decoded_exact.size() != n))
        return false;
    // The error a point gets in the header: the worse of the two decoders.
    auto point_error = [&](Vec3f f, Vec3f e, std::size_t k) {
        return std::max(distance(f, points[k]), exact ? distance(e, points[k]) : 0.0);
    };
    double other = 0, before = 0;
    for (std::size_t k = 0; k < i0; ++k) other = std::max(other, point_error(decoded[k], exact ? decoded_exact[k] : Vec3f{}, k));
    for (std::size_t k = 1; k < i0; ++k) before += distance(decoded[k - 1], decoded[k]);
    const Vec3f prev = decoded[i0 - 1];
    const std::array<std::uint16_t, 6> written = BlockView{block}.anchor_words();
    struct Candidate {
        double miss = 0, error = 0;
        std::array<std::uint16_t, 6> q{};
    };
    auto evaluate = [&](const std::array<std::uint16_t, 6>& q) {
        Candidate c{0, 0, q};
        double length = before;
        Vec3f from = prev;
        for (std::uint32_t a = 0; a < block_points; ++a) {
            const Vec3f f = float_anchor(h, &q[3 * a]);
            c.error = std::max(c.error, point_error(f, exact_anchor(h, &q[3 * a]), i0 + a));
            length += distance(from, f);
            from = f;
        }
        c.miss = std::fabs(length - target_length_mm);
        return c;
    };
    const Candidate now = evaluate(written);
    if (!(now.miss > other)) return false;  // within the fiber's point error already
    const double allowed = std::max({other, now.error, budget_mm});
    // Each anchor's words within `allowed` of its target (both decoders):
    // the written ones and their neighbours up to the allowance in quanta
    // (at most kEndAnchorReach either side).
    const int reach = std::clamp(int(std::ceil(allowed / (double(h.scaling) / 65535.0))), 1, kEndAnchorReach);
    std::vector<std::array<std::uint16_t, 3>> near[2];
    for (std::uint32_t a = 0; a < block_points; ++a)
        for (int dx = -reach; dx <= reach; ++dx)
            for (int dy = -reach; dy <= reach; ++dy)
                for (int dz = -reach; dz <= reach; ++dz) {
                    const int v[3] = {int(written[3 * a]) + dx, int(written[3 * a + 1]) + dy, int(written[3 * a + 2]) + dz};
                    if (std::min({v[0], v[1], v[2]}) < 0 || std::max({v[0], v[1], v[2]}) > 65535) continue;
                    const std::array<std::uint16_t, 3> q{std::uint16_t(v[0]), std::uint16_t(v[1]), std::uint16_t(v[2])};
                    if (point_error(float_anchor(h, q.data()), exact_anchor(h, q.data()), i0 + a) <= allowed) near[a].push_back(q);
                }
    Candidate best = now;
    auto consider = [&](const std::array<std::uint16_t, 3>& q0, const std::array<std::uint16_t, 3>* q1) {
        std::array<std::uint16_t, 6> q = written;
        std::copy(q0.begin(), q0.end(), q.begin());
        if (q1) {
            if (*q1 == q0) return;  // two anchors in one place: no direction between them
            std::copy(q1->begin(), q1->end(), q.begin() + 3);
        }
        const Candidate t = evaluate(q);
        if (t.miss < best.miss || (t.miss == best.miss && t.error < best.error)) best = t;
    };
    for (const auto& q0 : near[0]) {
        if (block_points == 1) consider(q0, nullptr);
        else
            for (const auto& q1 : near[1]) consider(q0, &q1);
    }
    if (best.q == written) return false;
    put_anchor_words(block, best.q);
    for (std::uint32_t a = 0; a < block_points; ++a) {
        decoded[i0 + a] = float_anchor(h, &best.q[3 * a]);
        if (exact) decoded_exact[i0 + a] = exact_anchor(h, &best.q[3 * a]);
    }
    return true;
}

double largest_error(std::span<const Vec3f> points, std::span<const Vec3f> decoded, std::span<const Vec3f> decoded_exact,
                     std::size_t m) {
    double worst2 = 0;
    for (std::size_t k = 0; k < m; ++k) {
        worst2 = std::max(worst2, distance2(decoded[k], points[k]));
        if (!decoded_exact.empty()) worst2 = std::max(worst2, distance2(decoded_exact[k], points[k]));
    }
    return std::sqrt(worst2);
}

namespace {

// The fraction `q` placed on the whole last step, for both decoders.
void place_fraction(const FiberEnd& end, std::uint16_t q, std::span<Vec3f> decoded, std::span<Vec3f> decoded_exact) {
    const std::size_t n = decoded.size();
    decoded[n - 1] = q == kWholeLastStep ? end.whole_step : place_end_point(decoded[n - 2], end.whole_step, q);
    if (!decoded_exact.empty())
        decoded_exact[n - 1] = q == kWholeLastStep ? end.whole_step_exact
                                                   : place_end_point(decoded_exact[n - 2], end.whole_step_exact, q);
}

// Places a fiber's end (its fraction, or its end anchors' rounding) with
// `budget_mm`; fills end.fraction and the length it leaves.
void place_end(const FftHeader& h, FiberEnd& end, std::uint8_t* last_block, std::span<const Vec3f> points,
               std::span<Vec3f> decoded, std::span<Vec3f> decoded_exact, double target_length_mm, double budget_mm) {
    const std::size_t n = points.size();
    if (end_fraction_applies(end.last_block_points)) {
        const std::uint16_t before = end.fraction;
        const double before_error = largest_error(points.subspan(n - 1), decoded.subspan(n - 1),
                                                  decoded_exact.empty() ? decoded_exact : decoded_exact.subspan(n - 1), 1);
        place_fraction(end, kWholeLastStep, decoded, decoded_exact);
        end.fraction = quantize_end_fraction(length_keeping_fraction(decoded, points, target_length_mm, budget_mm));
        place_fraction(end, end.fraction, decoded, decoded_exact);
        // The fraction's rounding and the exact decoder's end may take the
        // end a few nm past the budget, which bounds both decoders: back
        // towards the first placement a quantum at a time until within.
        auto end_error = [&] {
            return largest_error(points.subspan(n - 1), decoded.subspan(n - 1),
                                 decoded_exact.empty() ? decoded_exact : decoded_exact.subspan(n - 1), 1);
        };
        const double limit = std::max(budget_mm, before_error);
        while (budget_mm > 0 && end.fraction != before && end_error() > limit) {
            end.fraction = end.fraction > before ? end.fraction - 1 : end.fraction + 1;
            place_fraction(end, end.fraction, decoded, decoded_exact);
        }
        end.other_error_mm = largest_error(points, decoded, decoded_exact, n - 1);
    } else if (n > h.points_per_block && h.direction_bits() == 8) {
        round_end_anchors_keeping_length(h, last_block, end.last_block_points, points, decoded, decoded_exact,
                                         target_length_mm, budget_mm);
        end.other_error_mm = largest_error(points, decoded, decoded_exact, n - end.last_block_points);
    } else {
        return;  // an end anchor with no codes before it (or 16-bit): nothing to place
    }
    end.length_miss_mm = target_length_mm > 0 ? std::fabs(polyline_length(decoded) - target_length_mm) : 0.0;
}

}  // namespace

FiberEnd encode_keeping_end(const FiberEncoder& encoder, std::span<const Vec3f> points, bool short_tail,
                            double step_mm, std::uint32_t fiber_id, std::vector<std::uint8_t>& blocks,
                            std::vector<Vec3f>& decoded, std::vector<Vec3f>* decoded_exact,
                            std::vector<Vec3f>& scratch, double target_length_mm) {
    const FftHeader& h = encoder.header();
    const std::size_t n = points.size();
    FiberEnd end;
    end.last_block_points = n == 0 ? 0 : std::uint32_t(n - h.points_per_block * (encoder.block_count(n) - 1));
    const std::size_t first = decoded.size(), first_exact = decoded_exact ? decoded_exact->size() : 0;
    std::span<const Vec3f> coded = points;
    if (short_tail && n >= 2 && end_fraction_applies(end.last_block_points)) {  // the decoder walks whole steps: aim one at the end
        scratch.assign(points.begin(), points.end());
        scratch.back() = step_towards(points[n - 2], points[n - 1], step_mm);
        coded = scratch;
    }
    encoder.encode(coded, fiber_id, blocks, &decoded, decoded_exact);  // an end anchor is stored as is
    if (n < 2) return end;
    const std::span<Vec3f> dec = std::span<Vec3f>(decoded).subspan(first, n);
    const std::span<Vec3f> exact = decoded_exact && decoded_exact->size() == first_exact + n
                                       ? std::span<Vec3f>(*decoded_exact).subspan(first_exact, n)
                                       : std::span<Vec3f>();
    end.whole_step = dec[n - 1];
    if (!exact.empty()) end.whole_step_exact = exact[n - 1];
    place_end(h, end, &blocks[blocks.size() - h.block_bytes()], points, dec, exact, target_length_mm, 0);
    return end;
}

std::uint16_t place_end_within(const FftHeader& h, const FiberEnd& end, std::uint8_t* last_block,
                               std::span<const Vec3f> points, std::span<Vec3f> decoded,
                               std::span<Vec3f> decoded_exact, double target_length_mm, double budget_mm) {
    if (points.size() < 2) return end.fraction;
    FiberEnd again = end;
    place_end(h, again, last_block, points, decoded, decoded_exact, target_length_mm, budget_mm);
    return again.fraction;
}

}  // namespace fiblet::detail
