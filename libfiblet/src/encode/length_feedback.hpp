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
// LengthTails: only a block's last codes are searched again,
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

#include "core/points_avx2.hpp"
#include "core/vec_math.hpp"

namespace fiblet::detail {

// How many of a block's last points have their targets moved (linearly
// more towards the block's end), and the shares of the error tried (of at
// most the point error the block may have).
inline constexpr std::uint32_t kLengthFeedbackPoints = 12;
inline constexpr float kLengthFeedbackShares[] = {1.0f, 0.5f, 0.25f};
// Fixed-step form: the codes searched again at a block's end, and the share
// of the fiber's largest point error its length error may reach untouched:
// in the fiber's last kLengthFeedbackNearBlocks blocks before its last one,
// the near share; in earlier blocks, whose lag later blocks can still take
// back, the far share (the medium tractogram: 40 % fewer tail searches for
// the same mean length change; docs/encode.md).
inline constexpr std::uint32_t kLengthFeedbackTail = 24;
inline constexpr float kLengthFeedbackActShare = 0.25f;
inline constexpr float kLengthFeedbackFarActShare = 0.5f;
inline constexpr std::size_t kLengthFeedbackNearBlocks = 4;
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

#ifdef FIBLET_POINTS_AVX2
// The squared distances |a_i - b_i|^2 of eight points i (a and b: 24
// floats each, x y z interleaved), the scalar float operations
// ((dx dx + dy dy) + dz dz) on lanes holding the points out of order
// (squares_order()): the three registers of 24 floats are blended so that
// lane i holds one point's x, y or z, the y and z registers then rotated
// onto the x register's points.
__attribute__((target("avx2"))) inline __m256 squares8(const float* a, const float* b) {
    const __m256i rotate1 = _mm256_setr_epi32(1, 2, 3, 4, 5, 6, 7, 0), rotate2 = _mm256_setr_epi32(2, 3, 4, 5, 6, 7, 0, 1);
    __m256 r[3];
    for (int i = 0; i < 3; ++i) {
        const __m256 d = _mm256_sub_ps(_mm256_loadu_ps(a + 8 * i), _mm256_loadu_ps(b + 8 * i));
        r[i] = _mm256_mul_ps(d, d);
    }
    // Lanes: x0 x3 x6 x1 x4 x7 x2 x5; y5 y0 y3 y6 y1 y4 y7 y2; z2 z5 z0 z3 z6 z1 z4 z7.
    const __m256 x = _mm256_blend_ps(_mm256_blend_ps(r[0], r[1], 0b10010010), r[2], 0b00100100);
    const __m256 y = _mm256_blend_ps(_mm256_blend_ps(r[0], r[1], 0b00100100), r[2], 0b01001001);
    const __m256 z = _mm256_blend_ps(_mm256_blend_ps(r[0], r[1], 0b01001001), r[2], 0b10010010);
    return _mm256_add_ps(_mm256_add_ps(x, _mm256_permutevar8x32_ps(y, rotate1)), _mm256_permutevar8x32_ps(z, rotate2));
}
// The point each lane of squares8 holds; a permutation that is its own
// inverse, so permuting by it puts the lanes in order.
__attribute__((target("avx2"))) inline __m256i squares_order() { return _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5); }

// max_distance2 eight points at a time (the maximum does not depend on the
// lanes' order); returns where it stopped, *worst the maximum so far.
__attribute__((target("avx2"))) inline std::size_t max_distance2_avx2(const Vec3f* a, const Vec3f* b, std::size_t m,
                                                                   float* worst) {
    // Cast, not &a->x: a is null for no points.
    const auto *fa = reinterpret_cast<const float*>(a), *fb = reinterpret_cast<const float*>(b);
    __m256 w = _mm256_setzero_ps();
    std::size_t k = 0;
    for (; k + 8 <= m; k += 8) w = _mm256_max_ps(w, squares8(fa + 3 * k, fb + 3 * k));
    alignas(32) float lanes[8];
    _mm256_store_ps(lanes, w);
    for (const float v : lanes) *worst = std::max(*worst, v);
    return k;
}

// add_step_errors' terms norm(p[k] - p[k - 1]) - norm(t[k] - t[k - 1]) for
// k in [from, to), eight at a time, into terms[k - from]; returns where it
// stopped (from >= 1).
__attribute__((target("avx2"))) inline std::size_t step_terms_avx2(const Vec3f* points, const Vec3f* targets,
                                                                std::size_t from, std::size_t to, float* terms) {
    const float *fp = &points->x, *ft = &targets->x;
    std::size_t k = from;
    for (; k + 8 <= to; k += 8) {
        const __m256 p = _mm256_sqrt_ps(squares8(fp + 3 * k, fp + 3 * (k - 1)));
        const __m256 t = _mm256_sqrt_ps(squares8(ft + 3 * k, ft + 3 * (k - 1)));
        _mm256_storeu_ps(terms + (k - from), _mm256_permutevar8x32_ps(_mm256_sub_ps(p, t), squares_order()));
    }
    return k;
}
#endif

// The largest squared distance of a[k] from b[k], k < m (the points are
// finite, so the maximum does not depend on the order).
inline float max_distance2(const Vec3f* a, const Vec3f* b, std::size_t m) {
    float worst = 0;
    std::size_t k = 0;
#ifdef FIBLET_POINTS_AVX2
    if (use_avx2_loops()) k = max_distance2_avx2(a, b, m, &worst);
#endif
    for (; k < m; ++k) {
        const Vec3f d = a[k] - b[k];
        worst = std::max(worst, dot(d, d));
    }
    return worst;
}

// error + the sum of norm(points[k] - points[k - 1]) - norm(targets[k] -
// targets[k - 1]) over k in [from, to): the float terms a chunk at a time
// into a buffer (eight at a time with AVX2), then their double sum in four
// running sums (one chain of dependent additions was most of the length
// tails' own time), added in a fixed order.
inline double add_step_errors(double error, const Vec3f* points, const Vec3f* targets, std::size_t from,
                              std::size_t to) {
    constexpr std::size_t kChunk = 64;
    float terms[kChunk];
    for (std::size_t k0 = from; k0 < to; k0 += kChunk) {
        const std::size_t n = std::min(kChunk, to - k0);
        std::size_t i = 0;
#ifdef FIBLET_POINTS_AVX2
        if (use_avx2_loops()) i = step_terms_avx2(points, targets, k0, k0 + n, terms) - k0;
#endif
        for (; i < n; ++i) {
            const std::size_t k = k0 + i;
            terms[i] = norm(points[k] - points[k - 1]) - norm(targets[k] - targets[k - 1]);
        }
        double sums[4] = {0, 0, 0, 0};
        i = 0;
        for (; i + 4 <= n; i += 4)
            for (int j = 0; j < 4; ++j) sums[j] += terms[i + std::size_t(j)];
        for (; i < n; ++i) sums[0] += terms[i];
        error += (sums[0] + sums[1]) + (sums[2] + sums[3]);
    }
    return error;
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
        return max_distance2(decoded, targets.data() + first, m);
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
// of the fiber's largest point error (`far_act_share` more than `near`
// blocks before the fiber's last block), by moving the targets of the block's
// last `tail` points along the track (linearly more towards the end, by at
// most that point error, in shares 1, 1/2, 1/4: the first candidate that
// keeps the point error and shortens the lag is kept, as a smaller share
// moves the end less) and searching those points again; in the fiber's last
// adjustable block, all its points when the tail left more than `act`.
//
// Written as a sequence of searches the caller runs, so that the searches
// of several fibers can run together, one per SIMD lane (fiber_encoder.cpp,
// keep_length_tails):
//   while (tails.next(adjustable, search)) {
//       run search: block search.block's codes search.j0.. (its points
//       j0 + 2..) for search.targets, decoded into tails.candidate();
//       if (tails.judge()) the candidate's codes become the block's;
//   }
class LengthTails {
public:
    struct Search {
        std::uint32_t block = 0;
        std::size_t j0 = 0;                // the first code searched again
        std::span<const Vec3f> targets;    // its targets, moved
    };

    LengthTails(std::span<const Vec3f> targets, std::span<Vec3f> points, std::uint32_t ppb, std::uint32_t tail,
                float act_share, float far_act_share, std::size_t near)
        : targets_(targets), points_(points), ppb_(ppb), tail_(tail), near_(near) {
        const std::size_t n_points = points.size();
        if (n_points <= ppb) {  // one block: its length is the anchors' and the steps'
            b0_ = last_b0_ = 0;
            return;
        }
        fiber_max2_ = max_distance2(points.data(), targets.data(), n_points);
        act_ = act_share * std::sqrt(double(fiber_max2_));
        far_act_ = far_act_share * std::sqrt(double(fiber_max2_));
        last_b0_ = (n_points - 1) / ppb * ppb;
        last_block_error_ = add_step_errors(0, points.data(), targets.data(), last_b0_ + 1, n_points);
    }

    // The next search to run, false once the fiber is done. adjustable(b):
    // whether block b's codes may be searched again.
    template <class Adjustable>
    bool next(Adjustable&& adjustable, Search& out) {
        for (;;) {
            if (in_block_ && next_try(out)) return true;
            in_block_ = false;
            if (b0_ >= last_b0_) return false;
            start_block(adjustable);
        }
    }
    // Where the search writes its decoded points (as many as its targets).
    Vec3f* candidate() { return candidate_.data(); }
    // Judges the search's candidate: true when it is kept (its points are
    // then the fiber's, and the caller makes its codes the block's).
    bool judge() {
        const std::size_t j0 = m_ - codes_;
        ++share_;
        if (max_distance2(candidate_.data(), targets_.data() + first_ + j0, codes_) > fiber_max2_) return false;
        const double now = lag_ + (norm(points_[last_ + 1] - candidate_[codes_ - 1]) - norm(points_[last_ + 1] - points_[last_]));
        if (!(std::fabs(now) < best_)) return false;
        best_ = std::fabs(now);
        std::copy(candidate_.begin(), candidate_.end(), points_.begin() + std::ptrdiff_t(first_ + j0));
        share_ = std::size(kLengthFeedbackShares);  // the largest share the point error allows: smaller ones take back less
        return true;
    }

private:
    double error_of(std::size_t k) const {
        return norm(points_[k] - points_[k - 1]) - norm(targets_[k] - targets_[k - 1]);
    }
    // Block b0_'s length error; whether its tail is searched again.
    template <class Adjustable>
    void start_block(Adjustable&& adjustable) {
        const std::size_t b0 = b0_;
        b0_ += ppb_;
        const std::size_t n = std::min<std::size_t>(ppb_, points_.size() - b0);
        last_ = b0 + n - 1;
        error_ = add_step_errors(error_, points_.data(), targets_.data(), std::max<std::size_t>(b0, 1), last_ + 1);
        if (n <= 2) return;
        block_ = std::uint32_t(b0 / ppb_);
        lag_ = error_ + error_of(last_ + 1);
        last_chance_ = last_ + 1 == last_b0_;
        if (last_chance_) lag_ += last_block_error_;
        const bool far = (last_b0_ - b0) / ppb_ > near_;
        if (!(std::fabs(lag_) > (far ? far_act_ : act_)) || !adjustable(block_)) return;
        m_ = n - 2, first_ = b0 + 2, codes_ = std::min<std::size_t>(tail_, m_);
        best_ = std::fabs(lag_);
        const float reach = std::sqrt(fiber_max2_);
        move_ = std::clamp(float(lag_), -reach, reach);
        share_ = 0, whole_ = false, in_block_ = true;
    }
    // The block's next try: its tail at the next share, then (in the
    // fiber's last adjustable block, where the tail left more than `act`)
    // the whole block.
    bool next_try(Search& out) {
        if (share_ == std::size(kLengthFeedbackShares)) {
            // (A block no longer than the tail is tried twice: the second
            // time against the points the first kept.)
            if (whole_ || !(codes_ == m_ || (last_chance_ && best_ > act_))) return false;
            whole_ = true, codes_ = m_, share_ = 0;
        }
        const std::size_t j0 = m_ - codes_;
        move_tail_along_track(targets_, first_ + j0, last_, codes_, kLengthFeedbackShares[share_], move_, moved_);
        candidate_.resize(codes_);
        out = {block_, j0, std::span<const Vec3f>(moved_)};
        return true;
    }

    std::span<const Vec3f> targets_;
    std::span<Vec3f> points_;
    std::size_t ppb_, tail_, near_;
    float fiber_max2_ = 0;
    double act_ = 0, far_act_ = 0, last_block_error_ = 0;
    std::size_t b0_ = 0, last_b0_ = 0;  // the next block's first point; the fiber's last block's
    double error_ = 0;                  // decoded minus target length, up to the current point
    // The block being tried.
    bool in_block_ = false, last_chance_ = false, whole_ = false;
    std::uint32_t block_ = 0;
    std::size_t last_ = 0, first_ = 0, m_ = 0, codes_ = 0, share_ = 0;
    double lag_ = 0, best_ = 0;
    float move_ = 0;
    std::vector<Vec3f> moved_, candidate_;
};

}  // namespace fiblet::detail
