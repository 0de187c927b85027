// Per-point values (--point-values): an MRtrix3 track scalar file (.tsf, as
// tcksample writes it) or "dpv/NAME", a per-point array of the .fft's own
// DATA chunk. Either gives one finite number per point, fibers in file order.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace fiblet {
class FftFile;
}

namespace fiblet::viewer {

// The values of the .tsf `path` (fiblet::read_track_scalars) checked
// against the fibers' point counts
// (`fiber_points`, file order): Error{invalid_input} naming the first
// mismatch. A file resampled at compress time (`resampled`) holds other
// points than the tractogram the .tsf was sampled on; its message says so.
std::vector<float> read_point_values(const std::string& path, const std::vector<std::uint32_t>& fiber_points,
                                     bool resampled);

// "dpv/NAME" of the file's DATA chunk (one component, finite values);
// Error{invalid_argument} naming the file's per-point fields when absent.
// A resampled file's DATA was resampled with its points (PointFieldResampler).
std::vector<float> point_values_from_data(const FftFile& file, const std::string& name);

// What --point-values reads: "dpv/NAME" (when no such file exists) or a .tsf.
std::vector<float> read_point_value_source(const std::string& source, const FftFile& file,
                                           const std::vector<std::uint32_t>& fiber_points);

}  // namespace fiblet::viewer
