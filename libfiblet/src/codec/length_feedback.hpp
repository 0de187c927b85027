// Internal: keeping a fiber's length across its blocks (error feedback).
//
// Inside a block every decoded segment is one step long; what the codes
// change is where the block's last point lands along the track, and so the
// length of the bridge segment to the next block's first anchor, which lies
// on the target. Each block's lag is within the point error, but the lags
// of a fiber's blocks add up in its length. The feedback carries the
// fiber's length error so far (decoded minus target, the target segments
// stretched by the decoder's step scale) into the next block: the targets
// of the block's last points are moved along the track by the error the
// bridge would leave, the block is searched again, and the new codes are
// kept when they leave a smaller length error without a larger point error
// than the fiber already has. The fiber's last block is left to the end
// fraction (fiber_end_encoder.hpp), which places the end point.
//
// Fixed-step input (no end fraction) takes a cheaper form,
// feed_back_length_tails: only a block's last codes are searched again,
// with the block's own search, and only where the fiber's running length
// error exceeds a share of its point error; the fiber's last block, which
// no code can change, is paid for by the bridge before it (whose whole
// block is searched again when its tail could not).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "core/vec_math.hpp"

namespace fiblet::detail {

// How many of a block's last points have their targets moved (linearly
// more towards the block's end), and the shares of the error tried (of at
// most the point error the block may have).
inline constexpr std::uint32_t kLengthFeedbackPoints = 12;
inline constexpr float kLengthFeedbackShares[] = {1.0f, 0.5f, 0.25f};
// Fixed-step form: the codes searched again at a block's end, and the share
// of the fiber's largest point error its length error may reach untouched.
inline constexpr std::uint32_t kLengthFeedbackTail = 24;
inline constexpr float kLengthFeedbackActShare = 0.25f;
// The tails' lookahead search looks at least this far ahead: a tail's
// codes place the block's end, which one point of lookahead places less
// well (small-ifod1-step0.05, lookahead 1: lengths 3.25 um over a
// 2.76 um max error; tails at 2: 1.54 um; docs/encode.md).
inline constexpr unsigned kLengthFeedbackLookahead = 2;
// Fixed-step input keeping its lengths: blocks whose max error after the
// retry's beam still exceeds this multiple of the retry threshold are
// searched with this beam (at the sampling step, a smaller cap's rare
// outliers at sharp turns; measured in docs/encode.md).
inline constexpr float kLengthRescueOverRetry = 1.4f;
inline constexpr unsigned kLengthRescueBeam = 32;

// The largest squared distance of decoded[0, m) from targets[first, first + m).
inline float max_distance2(std::span<const Vec3f> targets, const Vec3f* decoded, std::size_t first, std::size_t m) {
    float worst = 0;
    for (std::size_t k = 0; k < m; ++k) {
        const Vec3f d = decoded[k] - targets[first + k];
        worst = std::max(worst, dot(d, d));
    }
    return worst;
}

// targets[from, last] into `moved`, the last `count` of them moved along the
// track by share x move (linearly less away from the end): a positive move
// takes them on towards the next point (a shorter bridge), a negative one back.
inline void move_tail_along_track(std::span<const Vec3f> targets, std::size_t from, std::size_t last, std::size_t count,
                                  float share, float move, std::vector<Vec3f>& moved) {
    moved.assign(targets.begin() + std::ptrdiff_t(from), targets.begin() + std::ptrdiff_t(last + 1));
    for (std::size_t j = 0; j < count; ++j) {
        const std::size_t k = last - j;
        const Vec3f along = targets[k + 1] - targets[k - 1];
        const float len = std::sqrt(dot(along, along));
        if (!(len > 0)) continue;
        const float w = float(count - j) / float(count);
        moved[k - from] = moved[k - from] + (share * w * move / len) * along;
    }
}

// `targets` and `points` (decoded) of one fiber, normalized coordinates;
// blocks of `ppb` points. Callbacks:
//   adjustable(b)          whether block b's codes may be searched again
//   search(b, t, decoded)  searches block b's codes for targets t (its
//                          points 2..n-1) into a candidate, decoded into `decoded`
//   keep(b)                the candidate becomes block b's codes
template <class Adjustable, class Search, class Keep>
void feed_back_length(std::span<const Vec3f> targets, std::span<Vec3f> points, std::uint32_t ppb, float stretch,
                      Adjustable&& adjustable, Search&& search, Keep&& keep) {
    const std::size_t n_points = points.size();
    if (n_points <= ppb) return;  // one block: the end fraction does it all
    thread_local std::vector<Vec3f> moved, candidate;
    auto error_of = [&](std::size_t k) { return norm(points[k] - points[k - 1]) - stretch * norm(targets[k] - targets[k - 1]); };
    auto max_error2 = [&](const Vec3f* decoded, std::size_t first, std::size_t m) {
        return max_distance2(targets, decoded, first, m);
    };
    // The point error the fiber has anyway: a block may go up to it.
    const float fiber_max2 = max_error2(points.data(), 0, n_points);
    double error = 0;  // decoded minus target length, up to the current point
    for (std::size_t b0 = 0; b0 < n_points; b0 += ppb) {
        const std::size_t n = std::min<std::size_t>(ppb, n_points - b0), last = b0 + n - 1;
        for (std::size_t k = std::max<std::size_t>(b0, 1); k <= last; ++k) error += error_of(k);  // bridge, anchors, codes
        if (n <= 2 || last + 1 >= n_points) continue;  // no codes, or the fiber's last block
        const auto b = std::uint32_t(b0 / ppb);
        // The error once the bridge to the next block is walked: the codes
        // change only this bridge (every segment inside the block is a step).
        const double lag = error + error_of(last + 1);
        if (!adjustable(b) || !(std::fabs(lag) > 0)) continue;
        const std::size_t m = n - 2, first = b0 + 2, moved_points = std::min<std::size_t>(kLengthFeedbackPoints, m);
        const float allowed2 = std::max(fiber_max2, max_error2(&points[first], first, m));
        double best = std::fabs(lag);
        // A move farther than the error the block may have cannot be followed.
        const float reach = std::sqrt(allowed2), move = std::clamp(float(lag), -reach, reach);
        for (const float share : kLengthFeedbackShares) {
            move_tail_along_track(targets, first, last, moved_points, share, move, moved);
            candidate.resize(m);
            search(b, std::span<const Vec3f>(moved), candidate.data());
            if (max_error2(candidate.data(), first, m) > allowed2) continue;
            const double now = std::fabs(error + norm(points[last + 1] - candidate[m - 1]) -
                                         stretch * norm(targets[last + 1] - targets[last]));
            if (!(now < best)) continue;
            best = now;
            std::copy(candidate.begin(), candidate.end(), points.begin() + std::ptrdiff_t(first));
            keep(b);
        }
    }
}

// Fixed-step form. The fiber's length error after each block's bridge
// (the fiber's last block counted with the bridge before it: its codes
// cannot change its length) is taken back, where it exceeds `act_share`
// of the fiber's largest point error, by moving the targets of the block's
// last `tail` points along the track (linearly more towards the end, by at
// most that point error, in shares 1, 1/2, 1/4: the first candidate that
// keeps the point error and shortens the lag is kept, as a smaller share
// moves the end less) and searching those points again; in the fiber's last
// adjustable block, all its points when the tail left more than `act`.
// Callbacks:
//   adjustable(b)                 whether block b's codes may be searched again
//   search(b, j0, t, decoded)     searches block b's codes j0.. (its points
//                                 j0 + 2..) for targets t into a candidate
//   keep(b, j0)                   the candidate becomes those codes
template <class Adjustable, class Search, class Keep>
void feed_back_length_tails(std::span<const Vec3f> targets, std::span<Vec3f> points, std::uint32_t ppb,
                            std::uint32_t tail, float act_share, Adjustable&& adjustable, Search&& search,
                            Keep&& keep) {
    const std::size_t n_points = points.size();
    if (n_points <= ppb) return;  // one block: its length is the anchors' and the steps'
    thread_local std::vector<Vec3f> moved, candidate;
    auto error_of = [&](std::size_t k) { return norm(points[k] - points[k - 1]) - norm(targets[k] - targets[k - 1]); };
    auto max_error2 = [&](const Vec3f* decoded, std::size_t first, std::size_t m) {
        return max_distance2(targets, decoded, first, m);
    };
    const float fiber_max2 = max_error2(points.data(), 0, n_points);
    const double act = act_share * std::sqrt(double(fiber_max2));
    // The fiber's last block: its segments are the anchors' and whole
    // steps whatever its codes; the block before it takes its error.
    const std::size_t last_b0 = (n_points - 1) / ppb * ppb;
    double last_block_error = 0;
    for (std::size_t k = last_b0 + 1; k < n_points; ++k) last_block_error += error_of(k);
    double error = 0;  // decoded minus target length, up to the current point
    for (std::size_t b0 = 0; b0 < last_b0; b0 += ppb) {
        const std::size_t n = std::min<std::size_t>(ppb, n_points - b0), last = b0 + n - 1;
        for (std::size_t k = std::max<std::size_t>(b0, 1); k <= last; ++k) error += error_of(k);
        if (n <= 2) continue;
        const auto b = std::uint32_t(b0 / ppb);
        double lag = error + error_of(last + 1);
        if (last + 1 == last_b0) lag += last_block_error;
        if (!(std::fabs(lag) > act) || !adjustable(b)) continue;
        const std::size_t m = n - 2, first = b0 + 2, tail_codes = std::min<std::size_t>(tail, m);
        const float allowed2 = fiber_max2;
        double best = std::fabs(lag);
        const float reach = std::sqrt(allowed2), move = std::clamp(float(lag), -reach, reach);
        // The block's tail, and where that leaves more than `act` in the
        // fiber's last adjustable block (no later block takes the rest),
        // the whole block.
        const bool last_chance = last + 1 == last_b0;
        for (const std::size_t codes : {tail_codes, m}) {
            if (codes != tail_codes && !(last_chance && best > act)) break;
            const std::size_t j0 = m - codes;
            for (const float share : kLengthFeedbackShares) {
                move_tail_along_track(targets, first + j0, last, codes, share, move, moved);
                candidate.resize(codes);
                search(b, j0, std::span<const Vec3f>(moved), candidate.data());
                if (max_error2(candidate.data(), first + j0, codes) > allowed2) continue;
                const double now =
                    lag + (norm(points[last + 1] - candidate[codes - 1]) - norm(points[last + 1] - points[last]));
                if (!(std::fabs(now) < best)) continue;
                best = std::fabs(now);
                std::copy(candidate.begin(), candidate.end(), points.begin() + std::ptrdiff_t(first + j0));
                keep(b, j0);
                break;  // the largest share the point error allows: smaller ones take back less
            }
        }
    }
}

}  // namespace fiblet::detail
