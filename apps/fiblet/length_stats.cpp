#include "length_stats.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "cli_common.hpp"
#include "fiblet/decode.hpp"

namespace fiblet::cli {

std::vector<double> decoded_fiber_lengths(const FftFile& file, unsigned threads) {
    std::vector<double> lengths;
    lengths.reserve(file.header().fibers);
    DecodeOptions options;
    options.threads = threads;
    decode_file(
        file,
        [&](std::uint64_t, const Streamlines& chunk) {
            for (std::size_t i = 0; i < chunk.size(); ++i) {
                double length = 0;
                for (std::uint64_t k = chunk.offsets[i] + 1; k < chunk.offsets[i + 1]; ++k) {
                    const float* a = &chunk.xyz[3 * (k - 1)];
                    const float* b = &chunk.xyz[3 * k];
                    length += std::hypot(double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]);
                }
                lengths.push_back(length);
            }
        },
        options);
    return lengths;
}

LengthStats length_stats(std::vector<double> v) {
    LengthStats s;
    s.count = v.size();
    if (v.empty()) {
        s.mean = s.median = s.std_dev = s.min = s.max = std::numeric_limits<double>::quiet_NaN();
        return s;
    }
    std::sort(v.begin(), v.end());
    double sum = 0;
    for (double x : v) sum += x;
    s.mean = sum / double(v.size());
    double squares = 0;
    for (double x : v) squares += (x - s.mean) * (x - s.mean);
    s.std_dev = v.size() > 1 ? std::sqrt(squares / double(v.size() - 1)) : std::numeric_limits<double>::quiet_NaN();
    const std::size_t mid = v.size() / 2;
    s.median = v.size() % 2 ? v[mid] : (v[mid - 1] + v[mid]) / 2;
    s.min = v.front(), s.max = v.back();
    return s;
}

std::string length_table(const LengthStats& s) {
    return fmt::format("{:>13}{:>13}{:>13}{:>13}{:>13}{:>12}\n{:>13.6g}{:>13.6g}{:>13.6g}{:>13.6g}{:>13.6g}{:>12}\n",
                       "mean", "median", "std. dev.", "min", "max", "count", s.mean, s.median, s.std_dev, s.min,
                       s.max, s.count);
}

std::string length_json(const LengthStats& s) {
    return Json{}
        .integer("count", s.count)
        .num("mean_mm", s.mean)
        .num("median_mm", s.median)
        .num("std_mm", s.std_dev)
        .num("min_mm", s.min)
        .num("max_mm", s.max)
        .render();
}

}  // namespace fiblet::cli
