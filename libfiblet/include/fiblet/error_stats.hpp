// fiblet — accumulating position errors (max, mean, RMS, percentiles).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace fiblet {

// Per-point errors in millimetres. Percentiles come from a histogram of
// 0.01 µm bins (exact max, mean and RMS), so memory stays constant. The
// histogram is stored in pages allocated on first use: errors cluster in a
// few pages, so an instance (one per encoding thread) costs kilobytes, not
// the 1.6 MB of the whole range.
class ErrorStats {
public:
    ErrorStats();
    ErrorStats(const ErrorStats& o) : pages_(o.pages_), count_(o.count_), sum_(o.sum_), sum_sq_(o.sum_sq_), max_(o.max_), worst_fiber_(o.worst_fiber_) {}
    ErrorStats& operator=(const ErrorStats& o) {
        pages_ = o.pages_, count_ = o.count_, sum_ = o.sum_, sum_sq_ = o.sum_sq_, max_ = o.max_, worst_fiber_ = o.worst_fiber_;
        page_ = nullptr, page_index_ = kNoPage;
        return *this;
    }
    ErrorStats(ErrorStats&& o) noexcept : ErrorStats(static_cast<const ErrorStats&>(o)) {}
    ErrorStats& operator=(ErrorStats&& o) noexcept { return *this = static_cast<const ErrorStats&>(o); }

    // Inline: compress adds several errors per point it writes. The page of
    // the last bin counted is cached (errors cluster in one or two pages).
    void add(double error_mm, std::uint64_t fiber) {
        ++count_;
        sum_ += error_mm;
        sum_sq_ += error_mm * error_mm;
        if (count_ == 1 || error_mm > max_) max_ = error_mm, worst_fiber_ = fiber;
        const double bin = error_mm * kBinsPerMm;  // a multiply, no division
        const std::size_t i = bin < double(kBins) ? std::size_t(bin) : kBins;
        if (i / kPageBins != page_index_) [[unlikely]] select_page(i / kPageBins);
        ++page_[i % kPageBins];
    }
    // The same as add() of each error in turn, but for the sums' rounding:
    // the errors of one call are summed in four lanes (error k in lane k % 4,
    // the same bits with or without SIMD), then added to the totals.
    void add_all(const double* errors_mm, std::size_t n, std::uint64_t fiber);
    // add_all of the square roots of squared errors (mm²), taken in the same
    // pass (correctly rounded, as std::sqrt): the callers measure squares.
    void add_all_roots(const double* squares_mm2, std::size_t n, std::uint64_t fiber);
    // The same of float squares, each root taken in float (std::sqrt of the
    // float, correctly rounded), then as a double.
    void add_all_roots(const float* squares_mm2, std::size_t n, std::uint64_t fiber);
    void merge(const ErrorStats& other);

    std::uint64_t count() const { return count_; }
    double max_mm() const { return max_; }
    double mean_mm() const { return count_ ? sum_ / double(count_) : 0.0; }
    double rms_mm() const;
    // p in [0, 100]; resolution 0.01 µm (errors above 2 mm are reported as the max).
    double percentile_mm(double p) const;
    // The fiber holding the largest error, and that error.
    std::uint64_t worst_fiber() const { return worst_fiber_; }

private:
    template <bool kRoots, class T>
    void add_each(const T* values, std::size_t n, std::uint64_t fiber);
    static constexpr double kBinsPerMm = 1e5;     // 0.01 µm bins
    static constexpr std::size_t kBins = 200000;  // up to 2 mm
    static constexpr std::size_t kPageBins = 2048;  // 20.48 µm per page
    static constexpr std::size_t kPageWords = 2 * kPageBins;  // a page's counts: two halves (add_each)
    static constexpr std::size_t kNoPage = ~std::size_t(0);
    void select_page(std::size_t p);

    // Empty until a bin of the page is counted; then kPageWords counts, a
    // bin's count the sum of its two halves' (add_each).
    std::vector<std::vector<std::uint64_t>> pages_;
    std::uint64_t count_ = 0;
    double sum_ = 0, sum_sq_ = 0, max_ = 0;
    std::uint64_t worst_fiber_ = 0;
    std::uint64_t* page_ = nullptr;  // pages_[page_index_], allocated
    std::size_t page_index_ = kNoPage;
};

}  // namespace fiblet
