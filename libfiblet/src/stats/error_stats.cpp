#include "fiblet/error_stats.hpp"

#include <algorithm>
#include <cmath>

namespace fiblet {

namespace {
constexpr double kBinMm = 1e-5;          // 0.01 µm
constexpr double kBinsPerMm = 1e5;
constexpr std::size_t kBins = 200000;    // up to 2 mm
constexpr std::size_t kPageBins = 2048;  // 20.48 µm per page
constexpr std::size_t kPages = (kBins + 1 + kPageBins - 1) / kPageBins;
}  // namespace

ErrorStats::ErrorStats() : pages_(kPages) {}

void ErrorStats::add(double e, std::uint64_t fiber) {
    ++count_;
    sum_ += e;
    sum_sq_ += e * e;
    if (count_ == 1 || e > max_) max_ = e, worst_fiber_ = fiber;
    const double bin = e * kBinsPerMm;  // a multiply: add() runs several times per point in compress
    const std::size_t i = bin < double(kBins) ? std::size_t(bin) : kBins;
    std::vector<std::uint64_t>& page = pages_[i / kPageBins];
    if (page.empty()) page.resize(kPageBins, 0);
    ++page[i % kPageBins];
}

void ErrorStats::merge(const ErrorStats& o) {
    if (o.count_ == 0) return;
    if (count_ == 0 || o.max_ > max_) worst_fiber_ = o.worst_fiber_;
    max_ = std::max(max_, o.max_);
    count_ += o.count_;
    sum_ += o.sum_;
    sum_sq_ += o.sum_sq_;
    for (std::size_t p = 0; p < kPages; ++p) {
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
