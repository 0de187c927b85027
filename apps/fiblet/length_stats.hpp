// The length statistics MRtrix3's tckstats prints (mean, median, sample
// standard deviation, min, max, count), measured on the decoded fibers of a
// .fft: what `fiblet stats FILE` reports without --reference.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fiblet/fft_file.hpp"

namespace fiblet::cli {

struct LengthStats {
    std::uint64_t count = 0;
    double mean = 0, median = 0, std_dev = 0, min = 0, max = 0;  // mm; std_dev over count - 1
};

// Lengths (mm, summed in double along each decoded polyline) of every fiber.
std::vector<double> decoded_fiber_lengths(const FftFile& file, unsigned threads);
LengthStats length_stats(std::vector<double> lengths_mm);

// tckstats' table: a header row, then one row of values (6 significant digits).
std::string length_table(const LengthStats& s);
// {"count": .., "mean_mm": .., "median_mm": .., "std_mm": .., "min_mm": .., "max_mm": ..}
std::string length_json(const LengthStats& s);

}  // namespace fiblet::cli
