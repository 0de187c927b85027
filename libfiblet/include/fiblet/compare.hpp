// fiblet — measuring a .fft against the .tck it was made from.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "fiblet/error_stats.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/geometry_error.hpp"

namespace fiblet {

struct Comparison {
    std::uint64_t fibers = 0, points = 0, blocks = 0;
    std::uint64_t fft_bytes = 0, reference_bytes = 0;
    // Files made from variable-step input (RSMP trailer chunk) are compared
    // with the reference resampled the same way; `error_vs_original` then
    // holds the distances from decoded points to the original polylines.
    bool resampled = false;
    ErrorStats error;
    ErrorStats error_vs_original;
    // Decoded vs the reference's own polylines (never resampled), both
    // ways, endpoints and lengths (fiblet/geometry_error.hpp).
    GeometryError geometry;
};

// Decodes every fiber and measures each decoded point against the reference
// (a .tck, .trk or TRX file: open_streamline_source).
// Throws Error{invalid_input} if the reference does not have the same
// fibers (count, or points per fiber).
Comparison compare_to_reference(const FftFile& fft, const std::string& tck_path, bool allow_count_mismatch = false,
                                const std::function<void(double)>& progress = {});

}  // namespace fiblet
