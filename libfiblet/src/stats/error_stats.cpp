#include "fiblet/error_stats.hpp"

#include <algorithm>
#include <cmath>

namespace fiblet {

namespace {
constexpr double kBinMm = 1e-5;  // 0.01 µm
}  // namespace

ErrorStats::ErrorStats() : pages_((kBins + 1 + kPageBins - 1) / kPageBins) {}

void ErrorStats::select_page(std::size_t p) {
    std::vector<std::uint64_t>& page = pages_[p];
    if (page.empty()) page.resize(kPageBins, 0);
    page_ = page.data(), page_index_ = p;
}

void ErrorStats::add_all(const double* errors, std::size_t n, std::uint64_t fiber) {
    std::uint64_t count = count_;
    double sum = sum_, sum_sq = sum_sq_, max = max_;
    std::uint64_t worst = worst_fiber_;
    // The page in locals too: the counts are 64-bit words, which the
    // compiler must otherwise assume may be page_index_ and reload it after
    // every count.
    std::uint64_t* page = page_;
    std::size_t page_index = page_index_;
    for (std::size_t k = 0; k < n; ++k) {
        const double e = errors[k];
        ++count;
        sum += e;
        sum_sq += e * e;
        if (count == 1 || e > max) max = e, worst = fiber;
        const double bin = e * kBinsPerMm;
        const std::size_t i = bin < double(kBins) ? std::size_t(bin) : kBins;
        if (i / kPageBins != page_index) [[unlikely]] {
            select_page(i / kPageBins);
            page = page_, page_index = page_index_;
        }
        ++page[i % kPageBins];
    }
    count_ = count, sum_ = sum, sum_sq_ = sum_sq, max_ = max, worst_fiber_ = worst;
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
        if (pages_[p].empty()) pages_[p].resize(kPageBins, 0);
        for (std::size_t i = 0; i < kPageBins; ++i) pages_[p][i] += o.pages_[p][i];
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
        seen += page[i % kPageBins];
        if (seen >= std::max<std::uint64_t>(rank, 1)) return std::min(double(i + 1) * kBinMm, max_);
    }
    return max_;
}

}  // namespace fiblet
