// fiblet — accumulating position errors (max, mean, RMS, percentiles).
#pragma once

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
    void add(double error_mm, std::uint64_t fiber);
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
    std::vector<std::vector<std::uint64_t>> pages_;  // empty until a bin of the page is counted
    std::uint64_t count_ = 0;
    double sum_ = 0, sum_sq_ = 0, max_ = 0;
    std::uint64_t worst_fiber_ = 0;
};

}  // namespace fiblet
