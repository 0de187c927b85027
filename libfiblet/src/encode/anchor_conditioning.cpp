#include "encode/anchor_conditioning.hpp"

#include <algorithm>
#include <cmath>

#include "core/block_geometry.hpp"
#include "fiblet/fft_format.hpp"

namespace fiblet::detail {

namespace {

Vec3d float_anchor(const std::array<std::uint32_t, 3>& q) {
    return {unpack_unorm16(std::uint16_t(q[0])), unpack_unorm16(std::uint16_t(q[1])), unpack_unorm16(std::uint16_t(q[2]))};
}
Vec3d exact_anchor(const std::array<std::uint32_t, 3>& q) {
    return {exact_unorm16(q[0]), exact_unorm16(q[1]), exact_unorm16(q[2])};
}

// How much a unit of divergence counts against a unit of anchor error in
// the choice of roundings. The robust code search absorbs much of the
// divergence that remains, while the anchor error is paid in full: on the
// stress test of first segments within 1 degree of the helper
// (exact_stress_test.cpp) 0.1 gives a max error of 1.98 um (the same
// fibers turned away from C: 1.37 um; no conditioning: 12.5 um); 0.03
// gives 4.31 (too little conditioning), 0.3 2.24 and 1 2.51 (anchors moved
// a whole quantum for little gain).
constexpr double kDivergenceWeight = 0.1;

// How many quanta the second anchor may move to leave the fallback's cone.
constexpr int kFallbackQuanta = 4;

double unorm16_value(double n) { return std::clamp(n, 0.0, 1.0) * 65535.0; }

// The larger of the two anchors' distances to where they should be.
double anchor_error(const AnchorWords& w, Vec3d n0, Vec3d n1) {
    const Vec3d e0 = exact_anchor(w.a0) - n0, e1 = exact_anchor(w.a1) - n1;
    return std::sqrt(std::max(dot(e0, e0), dot(e1, e1)));
}

}  // namespace

DecoderStarts decoder_starts(const AnchorWords& w) {
    DecoderStarts s;
    s.words = w;
    s.a0 = to_float(float_anchor(w.a0)), s.a1 = to_float(float_anchor(w.a1));
    const Vec3f axis = anchor_axis(s.a0, s.a1);
    s.frame = frame_from_axis(axis);
    s.exact0 = exact_anchor(w.a0), s.exact1 = exact_anchor(w.a1);
    const Vec3d exact_axis = exact_block_axis(s.exact0, s.exact1);
    s.exact_frame = exact_frame_from_axis(exact_axis);
    s.fallback = frame_uses_fallback(axis) || exact_frame_uses_fallback(exact_axis);
    return s;
}

double start_divergence(const DecoderStarts& s, double reach) {
    double frame2 = 0;
    for (int i = 0; i < 3; ++i) {
        const Vec3d d = s.exact_frame.c[i] - to_double(s.frame.c[i]);
        frame2 += dot(d, d);
    }
    const Vec3d da = s.exact1 - to_double(s.a1);
    return std::sqrt(dot(da, da)) + std::sqrt(frame2) * reach;
}

DecoderStarts condition_anchors(Vec3d n0, Vec3d n1, double reach, double threshold) {
    const double v[6] = {unorm16_value(n0.x), unorm16_value(n0.y), unorm16_value(n0.z),
                         unorm16_value(n1.x), unorm16_value(n1.y), unorm16_value(n1.z)};
    auto words = [&](unsigned up_mask, bool nearest) {
        AnchorWords w;
        for (int i = 0; i < 6; ++i) {
            const double r = nearest ? std::round(v[i]) : (up_mask >> i & 1) ? std::ceil(v[i]) : std::floor(v[i]);
            (i < 3 ? w.a0 : w.a1)[i % 3] = std::uint32_t(std::clamp(r, 0.0, 65535.0));
        }
        return w;
    };
    DecoderStarts best = decoder_starts(words(0, true));
    best.divergence = start_divergence(best, reach);
    bool fallback = best.fallback;
    if (!(best.divergence > threshold) && !fallback) return best;
    double best_cost = fallback ? INFINITY : anchor_error(best.words, n0, n1) + kDivergenceWeight * best.divergence;
    auto offer = [&](const AnchorWords& w) {
        // The divergence only adds to the anchor error: a rounding whose
        // anchors alone cost the best so far cannot win, and is not decoded.
        const double error = anchor_error(w, n0, n1);
        if (!(error < best_cost)) return;
        DecoderStarts s = decoder_starts(w);
        if (s.fallback) return;
        s.divergence = start_divergence(s, reach);
        const double cost = error + kDivergenceWeight * s.divergence;
        if (cost < best_cost) best_cost = cost, best = s, fallback = false;
    };
    for (unsigned mask = 0; mask < 64; ++mask) offer(words(mask, false));
    // Anchors on the grid round one way only: the second one moved by a
    // quantum on each axis turns the first axis away from C (a 0.1 mm step
    // turns by 1.7 degrees a quantum of a 200 mm box, the fallback's cone is 0.06).
    for (int q = 1; fallback && q <= kFallbackQuanta; ++q)
        for (int i = 0; i < 27; ++i) {
            if (i == 13) continue;  // no move: the nearest rounding, refused above
            AnchorWords w = words(0, true);
            for (int a = 0, code = i; a < 3; ++a, code /= 3)
                w.a1[a] = std::uint32_t(std::clamp<std::int64_t>(std::int64_t(w.a1[a]) + (code % 3 - 1) * q, 0, 65535));
            offer(w);
        }
    return best;
}

}  // namespace fiblet::detail
