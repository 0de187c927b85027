#include "fiblet/error_stats.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/grow.hpp"
#include "core/points_avx2.hpp"

namespace fiblet {

namespace {
constexpr double kBinMm = 1e-5;  // 0.01 µm
}  // namespace

ErrorStats::ErrorStats() : pages_((kBins + 1 + kPageBins - 1) / kPageBins) {}

void ErrorStats::select_page(std::size_t p) {
    std::vector<std::uint64_t>& page = pages_[p];
    if (page.empty()) page.resize(kPageWords, 0);
    page_ = page.data(), page_index_ = p;
}

namespace {

// An error from a value: the value, or the root of a squared error in the
// squares' own precision (a float square's root in float: its distance is
// float arithmetic already, and vsqrtps takes a fraction of vsqrtpd's time).
template <bool kRoots, class T>
double error_of(T v) {
    return kRoots ? double(std::sqrt(v)) : double(v);
}

// Four running sums of errors and of squares, error k into lane k % 4:
// the same bits whichever loop fills them.
struct LaneSums {
    double sum[4] = {0, 0, 0, 0}, sum_sq[4] = {0, 0, 0, 0};
    double total() const { return (sum[0] + sum[1]) + (sum[2] + sum[3]); }
    double total_sq() const { return (sum_sq[0] + sum_sq[1]) + (sum_sq[2] + sum_sq[3]); }
};

std::size_t bin_of(double e, double bins_per_mm, std::size_t bins) {
    const double bin = e * bins_per_mm;  // a multiply, no division
    return bin < double(bins) ? std::size_t(bin) : bins;
}

// The lowest and highest bin of a call's errors.
struct BinRange {
    std::int32_t lo = std::numeric_limits<std::int32_t>::max(), hi = 0;
    void add(std::int32_t b) { lo = std::min(lo, b), hi = std::max(hi, b); }
};

#ifdef FIBLET_POINTS_AVX2
// Errors [0, n / 4 * 4) (kRoots: the square roots of values, else values):
// the lane sums, the largest error and each error's bin (as bin_of), four
// at a time; returns the errors done.
template <bool kRoots, class T>
__attribute__((target("avx2"))) std::size_t sums_and_bins_avx2(const T* values, std::size_t n,
                                                               double bins_per_mm, std::size_t bins, LaneSums& lanes,
                                                               double& max, std::int32_t* bin, BinRange& range) {
    __m256d sum = _mm256_setzero_pd(), sum_sq = sum, largest = _mm256_set1_pd(max);
    const __m256d per_mm = _mm256_set1_pd(bins_per_mm), last = _mm256_set1_pd(double(bins));
    __m128i lowest_bin = _mm_set1_epi32(range.lo), highest_bin = _mm_set1_epi32(range.hi);
    std::size_t k = 0;
    for (; k + 4 <= n; k += 4) {
        __m256d e;
        if constexpr (sizeof(T) == sizeof(float)) {
            const __m128 v = _mm_loadu_ps(values + k);
            e = _mm256_cvtps_pd(kRoots ? _mm_sqrt_ps(v) : v);
        } else {
            const __m256d v = _mm256_loadu_pd(values + k);
            e = kRoots ? _mm256_sqrt_pd(v) : v;
        }
        sum = _mm256_add_pd(sum, e);
        sum_sq = _mm256_add_pd(sum_sq, _mm256_mul_pd(e, e));
        largest = _mm256_max_pd(e, largest);
        const __m256d b = _mm256_mul_pd(e, per_mm);
        // b < bins ? b : bins, truncated (bins fits 32 bits)
        const __m128i b32 = _mm256_cvttpd_epi32(_mm256_blendv_pd(last, b, _mm256_cmp_pd(b, last, _CMP_LT_OQ)));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(bin + k), b32);
        lowest_bin = _mm_min_epi32(lowest_bin, b32), highest_bin = _mm_max_epi32(highest_bin, b32);
    }
    alignas(16) std::int32_t lo[4], hi[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(lo), lowest_bin), _mm_store_si128(reinterpret_cast<__m128i*>(hi), highest_bin);
    range.lo = std::min(std::min(lo[0], lo[1]), std::min(lo[2], lo[3]));
    range.hi = std::max(std::max(hi[0], hi[1]), std::max(hi[2], hi[3]));
    _mm256_storeu_pd(lanes.sum, sum), _mm256_storeu_pd(lanes.sum_sq, sum_sq);
    alignas(32) double l[4];
    _mm256_store_pd(l, largest);
    max = std::max(std::max(l[0], l[1]), std::max(l[2], l[3]));
    return k;
}
#endif

}  // namespace

void ErrorStats::add_all(const double* errors, std::size_t n, std::uint64_t fiber) { add_each<false>(errors, n, fiber); }

void ErrorStats::add_all_roots(const double* squares, std::size_t n, std::uint64_t fiber) {
    add_each<true>(squares, n, fiber);
}

void ErrorStats::add_all_roots(const float* squares, std::size_t n, std::uint64_t fiber) {
    add_each<true>(squares, n, fiber);
}

template <bool kRoots, class T>
void ErrorStats::add_each(const T* values, std::size_t n, std::uint64_t fiber) {
    if (n == 0) return;
    thread_local std::vector<std::int32_t> bins;
    detail::grow(bins, n);
    LaneSums lanes;
    BinRange range;
    double max = error_of<kRoots>(values[0]);
    std::size_t k = 0;
#ifdef FIBLET_POINTS_AVX2
    if (detail::use_avx2_loops())
        k = sums_and_bins_avx2<kRoots, T>(values, n, kBinsPerMm, kBins, lanes, max, bins.data(), range);
#endif
    for (; k < n; ++k) {
        const double e = error_of<kRoots>(values[k]);
        lanes.sum[k % 4] += e;
        lanes.sum_sq[k % 4] += e * e;
        max = std::max(max, e);
        bins[k] = std::int32_t(bin_of(e, kBinsPerMm, kBins));
        range.add(bins[k]);
    }
    // The fiber holds the largest error if any of its errors is above the max so far.
    if (count_ == 0 || max > max_) max_ = max, worst_fiber_ = fiber;
    count_ += n;
    sum_ += lanes.total();
    sum_sq_ += lanes.total_sq();
    // Errors of one page (the usual: a page is 20.48 um wide): no page test
    // a count. Neighbouring points' errors often share a bin: the odd ones
    // are counted in the page's second half, so that a count seldom waits
    // on the store of the one just before.
    if (std::size_t(range.lo) / kPageBins == std::size_t(range.hi) / kPageBins) {
        const std::size_t p = std::size_t(range.hi) / kPageBins, first_bin = p * kPageBins;
        if (p != page_index_) select_page(p);
        std::uint64_t* const even = page_;
        std::uint64_t* const odd = page_ + kPageBins;
        std::size_t j = 0;
        for (; j + 2 <= n; j += 2) ++even[std::size_t(bins[j]) - first_bin], ++odd[std::size_t(bins[j + 1]) - first_bin];
        if (j < n) ++even[std::size_t(bins[j]) - first_bin];
        return;
    }
    // The page in locals: the counts are 64-bit words, which the compiler
    // must otherwise assume may be page_index_ and reload it after every count.
    std::uint64_t* page = page_;
    std::size_t page_index = page_index_;
    for (std::size_t j = 0; j < n; ++j) {
        const std::size_t i = std::size_t(bins[j]);
        if (i / kPageBins != page_index) [[unlikely]] {
            select_page(i / kPageBins);
            page = page_, page_index = page_index_;
        }
        ++page[i % kPageBins + (j & 1) * kPageBins];
    }
}

void ErrorStats::merge(const ErrorStats& o) {
    if (o.count_ == 0) return;
    if (count_ == 0 || o.max_ > max_) worst_fiber_ = o.worst_fiber_;
    max_ = std::max(max_, o.max_);
    count_ += o.count_;
    sum_ += o.sum_;
    sum_sq_ += o.sum_sq_;
    for (std::size_t p = 0; p < pages_.size(); ++p) {
        if (o.pages_[p].empty()) continue;
        if (pages_[p].empty()) pages_[p].resize(kPageWords, 0);
        for (std::size_t i = 0; i < kPageWords; ++i) pages_[p][i] += o.pages_[p][i];
    }
}

double ErrorStats::rms_mm() const { return count_ ? std::sqrt(sum_sq_ / double(count_)) : 0.0; }

double ErrorStats::percentile_mm(double p) const {
    if (count_ == 0) return 0.0;
    const auto rank = std::uint64_t(std::ceil(std::clamp(p, 0.0, 100.0) / 100.0 * double(count_)));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < kBins; ++i) {
        const std::vector<std::uint64_t>& page = pages_[i / kPageBins];
        if (page.empty()) {  // a page never counted: skip it whole
            i += kPageBins - 1 - i % kPageBins;
            continue;
        }
        seen += page[i % kPageBins] + page[kPageBins + i % kPageBins];
        if (seen >= std::max<std::uint64_t>(rank, 1)) return std::min(double(i + 1) * kBinMm, max_);
    }
    return max_;
}

}  // namespace fiblet
