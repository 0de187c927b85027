#include "encode/parameters.hpp"

#include <algorithm>
#include <cmath>

#include "core/points_avx2.hpp"
#include "core/vec_math.hpp"
#include "fiblet/resample.hpp"

namespace fiblet::detail {

namespace {
// Bins of (1 - dot) / 2 = sin^2(angle / 2) in [0, 1]: 0.013 degree wide at
// a 15 degree turn.
constexpr std::size_t kTurnBins = 1u << 15;
}  // namespace

TurnStatistics::TurnStatistics(std::uint32_t points_per_block, std::size_t kept_blocks)
    : bins_(kTurnBins + 1, 0), points_per_block_(std::max<std::uint32_t>(points_per_block, 1)), kept_blocks_(kept_blocks) {}

void TurnStatistics::add_fiber(std::span<const Vec3f> f) { add_turns(f, [](double n2, std::size_t) { return std::sqrt(n2); }); }

#ifdef FIBLET_POINTS_AVX2
namespace {

// fiber_segments' first segments, eight at a time; returns how many.
__attribute__((target("avx2"))) std::size_t segments_avx2(const Vec3f* f, std::size_t segments, FiberSegments& out) {
    double *length = out.length.data(), *ux = out.ux.data(), *uy = out.uy.data(), *uz = out.uz.data();
    const __m256d one = _mm256_set1_pd(1.0), zero = _mm256_setzero_pd();
    __m256d positive = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
    std::size_t s = 0;
    for (; s + 8 <= segments; s += 8) {  // reads points s .. s + 8
        __m256d x[2], y[2], z[2];
        deltas8(f + s, x, y, z);
        for (int h = 0; h < 2; ++h) {
            const std::size_t at = s + 4 * std::size_t(h);
            const __m256d len = _mm256_sqrt_pd(norm2(x[h], y[h], z[h])), inv = _mm256_div_pd(one, len);
            _mm256_storeu_pd(length + at, len);
            _mm256_storeu_pd(ux + at, _mm256_mul_pd(x[h], inv)), _mm256_storeu_pd(uy + at, _mm256_mul_pd(y[h], inv));
            _mm256_storeu_pd(uz + at, _mm256_mul_pd(z[h], inv));
            positive = _mm256_and_pd(positive, _mm256_cmp_pd(len, zero, _CMP_GT_OQ));  // NaN: not positive
        }
    }
    out.positive = _mm256_movemask_pd(positive) == 0xf;
    return s;
}

// add_turns' turns of a fiber none of whose segments has length 0 (those
// are skipped there), four at a time: s2[t] = sin^2 of the turn between
// segments t and t + 1 (at point t + 1), with the same double operations,
// and its histogram bin. Returns the turns (segments - 1).
__attribute__((target("avx2"))) std::size_t turn_sizes_avx2(const FiberSegments& seg, std::vector<double>& s2,
                                                            std::vector<std::int32_t>& bin) {
    const std::size_t n = seg.length.size();
    s2.resize(n - 1), bin.resize(n - 1);
    const double *ux = seg.ux.data(), *uy = seg.uy.data(), *uz = seg.uz.data();
    const __m256d one = _mm256_set1_pd(1.0), quarter = _mm256_set1_pd(0.25), bins = _mm256_set1_pd(double(kTurnBins));
    std::size_t t = 0;
    for (; t + 5 <= n; t += 4) {  // std::min(v, 1.0) is (1.0 < v) ? 1.0 : v, as minpd(1.0, v)
        const __m256d ex = _mm256_sub_pd(_mm256_loadu_pd(ux + t + 1), _mm256_loadu_pd(ux + t)),
                      ey = _mm256_sub_pd(_mm256_loadu_pd(uy + t + 1), _mm256_loadu_pd(uy + t)),
                      ez = _mm256_sub_pd(_mm256_loadu_pd(uz + t + 1), _mm256_loadu_pd(uz + t));
        const __m256d v = _mm256_min_pd(one, _mm256_mul_pd(quarter, norm2(ex, ey, ez)));
        _mm256_storeu_pd(s2.data() + t, v);
        // In [0, 2^15]: the truncation of a 32-bit conversion is the size_t one.
        _mm_storeu_si128(reinterpret_cast<__m128i*>(bin.data() + t), _mm256_cvttpd_epi32(_mm256_mul_pd(v, bins)));
    }
    for (; t + 1 < n; ++t) {
        const double ex = ux[t + 1] - ux[t], ey = uy[t + 1] - uy[t], ez = uz[t + 1] - uz[t];
        s2[t] = std::min(0.25 * (ex * ex + ey * ey + ez * ez), 1.0);
        bin[t] = std::int32_t(s2[t] * float(kTurnBins));
    }
    return n - 1;
}

}  // namespace
#endif

// The same double operations as distance() (a difference's square is its
// negation's; vsqrtpd rounds correctly) and as add_turns' directions.
void fiber_segments(std::span<const Vec3f> f, FiberSegments& out) {
    const std::size_t n = f.empty() ? 0 : f.size() - 1;
    for (auto* v : {&out.length, &out.ux, &out.uy, &out.uz}) v->resize(n);
    std::size_t s = 0;
    out.positive = true;
#ifdef FIBLET_POINTS_AVX2
    if (use_avx2_loops()) s = segments_avx2(f.data(), n, out);
#endif
    for (; s < n; ++s) {
        const double dx = double(f[s + 1].x) - f[s].x, dy = double(f[s + 1].y) - f[s].y, dz = double(f[s + 1].z) - f[s].z;
        const double len = std::sqrt(dx * dx + dy * dy + dz * dz), inv = 1.0 / len;
        out.length[s] = len;
        out.ux[s] = dx * inv, out.uy[s] = dy * inv, out.uz[s] = dz * inv;
        out.positive = out.positive && len > 0;
    }
}

void TurnStatistics::add_fiber(std::span<const Vec3f> f, const FiberSegments& segments) {
#ifdef FIBLET_POINTS_AVX2
    // The common case in vectors: no segment of length 0 (or NaN).
    if (segments.positive && f.size() >= 6 && use_avx2_loops()) {
        thread_local std::vector<double> s2;
        thread_local std::vector<std::int32_t> bin;
        const std::size_t turns = turn_sizes_avx2(segments, s2, bin);
        double fiber_max = -1;
        std::size_t at = 0;
        for (std::size_t t = 0; t < turns; ++t) {
            if (s2[t] > fiber_max) fiber_max = s2[t], at = t + 1;
            ++bins_[std::size_t(bin[t])];
        }
        count_ += turns;
        return keep_sharpest(f, fiber_max, at);
    }
#endif
    add_turns(f, [&](double, std::size_t i) { return segments.length[i - 1]; });
}

template <class SegmentLength>
void TurnStatistics::add_turns(std::span<const Vec3f> f, SegmentLength segment_length) {
    // Double: a float's square overflows beyond 1e19 mm and vanishes below
    // 1e-19 mm, and every float tractogram, whatever its units, must see
    // its turns (a cap sized for no turn at all wrecks the encoding).
    double px = 0, py = 0, pz = 0;
    bool have = false;
    double fiber_max = -1;  // largest sin^2(angle / 2) of the fiber
    std::size_t at = 0;
    for (std::size_t i = 1; i < f.size(); ++i) {
        double dx = double(f[i].x) - f[i - 1].x, dy = double(f[i].y) - f[i - 1].y, dz = double(f[i].z) - f[i - 1].z;
        const double n2 = dx * dx + dy * dy + dz * dz;
        if (!(n2 > 0)) continue;
        const double inv = 1.0 / segment_length(n2, i);
        dx *= inv, dy *= inv, dz *= inv;
        if (have) {
            const double ex = dx - px, ey = dy - py, ez = dz - pz;
            const double s2 = std::min(0.25 * (ex * ex + ey * ey + ez * ez), 1.0);
            if (s2 > fiber_max) fiber_max = s2, at = i - 1;  // the turn at point i - 1
            ++bins_[std::size_t(s2 * float(kTurnBins))];
            ++count_;
        }
        px = dx, py = dy, pz = dz, have = true;
    }
    keep_sharpest(f, fiber_max, at);
}

// The fiber's sharpest turn (sin^2 fiber_max, at point `at`; -1: none)
// into the smallest dot, and its block into the sharpest blocks if it is one.
void TurnStatistics::keep_sharpest(std::span<const Vec3f> f, double fiber_max, std::size_t at) {
    if (fiber_max < 0) return;
    const double fiber_min = 1.0 - 2.0 * fiber_max;  // the dot of the sharpest turn
    min_dot_ = std::min(min_dot_, fiber_min);
    if (!wants(fiber_min)) return;
    const std::size_t b0 = at / points_per_block_ * points_per_block_;
    const std::size_t b1 = std::min(f.size(), b0 + points_per_block_);
    keep(fiber_min, std::vector<Vec3f>(f.begin() + std::ptrdiff_t(b0), f.begin() + std::ptrdiff_t(b1)));
}

bool TurnStatistics::wants(double dot) const {
    return kept_blocks_ > 0 && (sharpest_.size() < kept_blocks_ || dot < sharpest_.front().first);
}

void TurnStatistics::keep(double dot, std::vector<Vec3f> block) {
    auto by_dot = [](const auto& a, const auto& b) { return a.first < b.first; };
    if (sharpest_.size() == kept_blocks_) {
        std::pop_heap(sharpest_.begin(), sharpest_.end(), by_dot);
        sharpest_.pop_back();
    }
    sharpest_.emplace_back(dot, std::move(block));
    std::push_heap(sharpest_.begin(), sharpest_.end(), by_dot);
}

void TurnStatistics::merge(const TurnStatistics& other) {
    for (std::size_t i = 0; i < bins_.size() && i < other.bins_.size(); ++i) bins_[i] += other.bins_[i];
    count_ += other.count_;
    min_dot_ = std::min(min_dot_, other.min_dot_);
    for (const auto& [dot, block] : other.sharpest_)
        if (wants(dot)) keep(dot, block);
}

double TurnStatistics::dot_at_percentile(double p) const {
    if (count_ == 0 || p >= 100) return min_dot_;
    const auto rank = std::uint64_t(std::ceil(std::max(p, 0.0) / 100.0 * double(count_)));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < bins_.size(); ++i) {
        seen += bins_[i];
        if (seen >= rank) {
            const double s2 = std::min(1.0, double(i + 1) / double(kTurnBins));  // the bin's upper edge
            return std::max(min_dot_, 1.0 - 2.0 * s2);
        }
    }
    return min_dot_;
}

std::vector<std::vector<Vec3f>> TurnStatistics::sharpest_blocks() const {
    std::vector<std::vector<Vec3f>> out;
    for (const auto& [dot, points] : sharpest_) out.push_back(points);
    return out;
}

void FiberSample::offer(std::span<const Vec3f> fiber) {
    if (seen_++ % stride_ != 0) return;
    // An empty fiber counts as one point, so that the budget bounds the
    // sample's fibers too (2^24 empty streamlines were all kept).
    auto weight = [](std::size_t n) { return std::max<std::size_t>(n, 1); };
    fibers_.emplace_back(fiber.begin(), fiber.end());
    points_ += weight(fiber.size());
    while (points_ > max_points_ && fibers_.size() > 1) {
        // Keep every other fiber of the sample: those at multiples of 2 * stride.
        std::size_t w = 0;
        points_ = 0;
        for (std::size_t i = 0; i < fibers_.size(); i += 2, ++w) {
            points_ += weight(fibers_[i].size());
            if (w != i) fibers_[w] = std::move(fibers_[i]);
        }
        fibers_.resize(w);
        stride_ *= 2;
    }
}

SampleError measure(const TuningSet& set, const FiberEncoder& encoder) {
    std::vector<std::uint8_t> blocks;
    std::vector<Vec3f> decoded;
    double sum = 0, max = 0, length_change = 0, length_drift = 0, length = 0;
    std::size_t n = 0;
    auto encode = [&](std::span<const Vec3f> points, bool in_mean) {
        blocks.clear();
        decoded.clear();
        encoder.encode(points, 0, blocks, &decoded);
        double change = 0, target_length = 0;
        for (std::size_t k = 0; k < points.size(); ++k) {
            const double e = distance(decoded[k], points[k]);
            max = std::max(max, e);
            if (in_mean) sum += e;
            if (k == 0) continue;
            const double segment = distance(points[k], points[k - 1]);
            change += distance(decoded[k], decoded[k - 1]) - segment;
            target_length += segment;
        }
        if (in_mean) n += points.size(), length_change += std::fabs(change), length_drift += change, length += target_length;
    };
    for (const auto& fiber : set.fibers) encode(fiber, true);
    for (const auto& block : set.sharp_blocks) encode(block, false);
    const double fibers = double(set.fibers.size());
    if (set.fibers.empty()) return {n ? sum / double(n) : 0.0, max};
    return {n ? sum / double(n) : 0.0, max, length_change / fibers, length_drift / fibers, length / fibers};
}

TunedParameters tune_parameters(const TuningSet& given, const TurnStatistics& turns, FftHeader h,
                                const SearchOptions& search, double sampling_step_mm,
                                std::optional<float> fixed_ratio, std::optional<double> fixed_scale,
                                bool keep_lengths, float max_ratio) {
    // Fibers to resample are resampled once here, not at every measure().
    TuningSet resampled_set;
    if (given.resample_step_mm > 0) {
        resampled_set.sharp_blocks = given.sharp_blocks;
        resampled_set.fibers.resize(given.fibers.size());
        for (std::size_t i = 0; i < given.fibers.size(); ++i)
            resample_fixed_step(given.fibers[i], given.resample_step_mm, resampled_set.fibers[i], kWrittenCurve);
    }
    const TuningSet& set = given.resample_step_mm > 0 ? resampled_set : given;
    constexpr double kDefaultScale = 1.0005;
    TunedParameters best{fixed_ratio.value_or(compute_ratio(h.scaling, sampling_step_mm, turns.min_dot())),
                         fixed_scale.value_or(1.0), search};
    const bool have_data = !set.fibers.empty() || !set.sharp_blocks.empty();
    const bool auto_retry = search.retry_beam_width > 0 && !(search.retry_error_mm > 0);
    if (!have_data || !(sampling_step_mm > 0)) {
        if (auto_retry) best.search.retry_beam_width = 0;  // no data to set a threshold from
        return best;
    }
    auto step_for = [&](double scale) { return float(sampling_step_mm * scale / h.scaling); };

    // 16-bit codes are 16 times finer: a turn sharper than the cap costs far
    // more than the finer codes of a smaller cap save, and the zig-zag lag
    // (angle^2 / 2) is 256 times smaller: the cap holds every turn and the
    // decoder walks the sampling step.
    if (h.direction_bits() == 16) {
        if (!fixed_ratio) fixed_ratio = best.ratio;
        if (!fixed_scale) fixed_scale = 1.0;
    }
    // Cap ratio: turn angles from the 99.9th percentile to the sharpest.
    std::vector<float> ratios;
    if (fixed_ratio) {
        ratios.push_back(*fixed_ratio);
    } else {
        const double lo = std::acos(std::clamp(turns.dot_at_percentile(99.9), -1.0, 1.0));
        const double hi = std::acos(std::clamp(turns.min_dot(), -1.0, 1.0));
        constexpr int kRatios = 6;
        for (int i = 0; i < kRatios; ++i) {
            const double angle = hi - (hi - lo) * i / (kRatios - 1);
            const float r = compute_ratio(h.scaling, sampling_step_mm, std::cos(angle));
            if (r > max_ratio * (1 + 1e-6f)) continue;
            if (ratios.empty() || std::fabs(r - ratios.back()) > 1e-4f * ratios.back()) ratios.push_back(r);
        }
        if (ratios.empty()) ratios.push_back(max_ratio);
    }
    const double scale0 = fixed_scale.value_or(kDefaultScale);
    double best_objective = INFINITY;
    std::optional<FiberEncoder> best_encoder;
    for (float r : ratios) {
        h.ratio = r;
        h.step = step_for(scale0);
        FiberEncoder encoder = FiberEncoder(h, search).with_length_feedback(keep_lengths ? 1.0f : 0.0f, keep_lengths);
        if (auto_retry) {
            SearchOptions first = search;
            first.retry_beam_width = 0;
            SearchOptions retry = search;
            retry.retry_error_mm = kRetryOverMeanError * measure(set, encoder.with_search(first)).mean_mm;
            if (!(retry.retry_error_mm > 0)) retry.retry_beam_width = 0;  // an exact encoding: nothing to retry
            encoder = encoder.with_search(retry);
        }
        const SampleError e = measure(set, encoder);
        if (e.objective() < best_objective) best_objective = e.objective(), best.ratio = r, best_encoder.emplace(std::move(encoder));
    }
    best.step_scale = scale0;
    if (!fixed_scale) {
        for (double scale : {1.0, 1.00025, 1.00075, 1.001, 1.0015}) {
            const SampleError e = measure(set, best_encoder->with_step(step_for(scale)));
            if (e.objective() < best_objective) best_objective = e.objective(), best.step_scale = scale;
        }
    }
    best.encoder = best_encoder->with_step(step_for(best.step_scale));
    best.search = best.encoder->search();
    return best;
}

namespace {
// The search's codes leave a systematic length drift at the sampling step
// (the lookahead's paths run a little longer than the input's, greedy
// aiming's zig-zag a little shorter): the decoder step is scaled against
// the sample's mean drift, so that the tail feedback is left with each
// fiber's own scatter (fewer blocks to search again, smaller length errors).
// Measured without the feedback, which would hide the drift.
constexpr double kMaxDriftCorrection = 1e-3;
void centre_length_drift(const TuningSet& fibers, const FftHeader& h, double sampling_step_mm, TunedParameters& kept) {
    const SampleError drift = measure(fibers, kept.encoder->with_length_feedback(0.0f, false));
    if (!(drift.length_mm > 0)) return;
    // In steps of 1e-5 (the report prints the scale; a float step resolves 6e-8).
    const double wanted = std::round(kept.step_scale * (1 - drift.length_drift_mm / drift.length_mm) * 1e5) / 1e5;
    const double scale = std::clamp(wanted, 1 - kMaxDriftCorrection, 1 + kMaxDriftCorrection);
    kept.step_scale = scale;
    kept.encoder = kept.encoder->with_step(float(sampling_step_mm * scale / h.scaling));
}
}  // namespace

bool keep_fixed_step_lengths(const TuningSet& set, const TurnStatistics& turns, TunedParameters& tuned, FftHeader h,
                             double sampling_step_mm, std::optional<float> fixed_ratio, std::optional<double> fixed_scale) {
    if (h.direction_bits() == 16 || set.fibers.empty() || !(sampling_step_mm > 0)) return false;
    // The cap is tuned again at the sampling step among caps no larger than
    // the tuned one: there the rescue beam holds a small cap's outliers,
    // which the sample's max cannot tell (measured on small-ifod1-step0.05:
    // the cap tuned at x1.0005, 0.066, gives a mean of 0.92 um at the
    // sampling step; the one the full sweep picks there, 0.084, 1.01 um).
    // (With the retry threshold already tuned: one sample encode per cap.)
    TunedParameters kept = tune_parameters(set, turns, h, tuned.search, sampling_step_mm, fixed_ratio,
                                           fixed_scale.value_or(1.0), true, tuned.ratio);
    if (!kept.encoder) return false;
    const TuningSet fibers{set.fibers, {}, 0};
    const SampleError e = measure(fibers, *kept.encoder);
    if (!(e.length_change_mm <= kKeepLengthsShare * e.max_mm)) return false;
    if (!fixed_scale) centre_length_drift(fibers, h, sampling_step_mm, kept);
    tuned = std::move(kept);
    return true;
}

}  // namespace fiblet::detail
