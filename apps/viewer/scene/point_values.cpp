#include "scene/point_values.hpp"

#include <cmath>
#include <filesystem>

#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/streamline_field.hpp"
#include "fiblet/tck.hpp"

namespace fiblet::viewer {

std::vector<float> read_point_values(const std::string& path, const std::vector<std::uint32_t>& fiber_points,
                                     bool resampled) {
    const std::vector<std::vector<float>> tracks = fiblet::read_track_scalars(path);
    const std::string why = resampled ? " (this .fft was resampled at compress time: sample the decompressed "
                                        "tractogram, or use the DATA chunk's dpv/NAME)"
                                      : "";
    if (tracks.size() != fiber_points.size())
        throw Error(Errc::invalid_input, path + ": " + std::to_string(tracks.size()) + " streamlines for the .fft's " +
                                             std::to_string(fiber_points.size()) + why);
    std::vector<float> out;
    for (std::size_t f = 0; f < tracks.size(); ++f) {
        if (tracks[f].size() != fiber_points[f])
            throw Error(Errc::invalid_input, path + ": streamline " + std::to_string(f) + " has " +
                                                 std::to_string(tracks[f].size()) + " values for " +
                                                 std::to_string(fiber_points[f]) + " points" + why);
        out.insert(out.end(), tracks[f].begin(), tracks[f].end());
    }
    return out;
}

std::vector<float> point_values_from_data(const FftFile& file, const std::string& name) {
    std::string available;
    for (const StreamlineField& f : file.streamline_fields()) {
        if (f.scope() != FieldScope::point) continue;
        if (f.name != name) {
            available += (available.empty() ? "" : ", ") + f.name;
            continue;
        }
        if (f.components != 1)
            throw Error(Errc::invalid_input, file.path() + ": " + name + " holds " + std::to_string(f.components) +
                                                 " values per point (one is needed for a colour map)");
        std::vector<float> out(f.rows());
        for (std::uint64_t r = 0; r < f.rows(); ++r) {
            out[r] = narrow_to_float(f.at(r, 0));
            if (!std::isfinite(out[r]))
                throw Error(Errc::invalid_input, file.path() + ": " + name + " of point " + std::to_string(r) + " is not a finite number");
        }
        return out;
    }
    throw Error(Errc::invalid_argument, file.path() + " carries no per-point data " + name + " (" +
                                            (available.empty() ? "it has none" : "it has: " + available) + ")");
}

std::vector<float> read_point_value_source(const std::string& source, const FftFile& file,
                                           const std::vector<std::uint32_t>& fiber_points) {
    const bool from_data = source.rfind("dpv/", 0) == 0 && source.size() > 4 && !std::filesystem::exists(source);
    if (!from_data) return read_point_values(source, fiber_points, file.resampling().has_value());
    std::vector<float> values = point_values_from_data(file, source);
    std::uint64_t points = 0;
    for (const std::uint32_t n : fiber_points) points += n;
    if (values.size() != points)
        throw Error(Errc::invalid_input, file.path() + ": " + source + " holds " + std::to_string(values.size()) +
                                             " values for " + std::to_string(points) + " points");
    return values;
}

}  // namespace fiblet::viewer
