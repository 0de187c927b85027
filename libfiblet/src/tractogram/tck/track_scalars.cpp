// MRtrix3 track scalar files (.tsf, tcksample's output): the .tck header
// with its own first line, then one value per point in the header's
// datatype, NaN after each streamline, and Inf or the end of the file.
#include <cmath>
#include <fstream>

#include "fiblet/error.hpp"
#include "fiblet/streamline_field.hpp"
#include "fiblet/tck.hpp"
#include "tractogram/tck/track_header.hpp"

namespace fiblet {
namespace {

// The values of the data section as the datatype says (Float32/64, LE/BE).
std::vector<double> decode_values(TckDataType type, const std::string& data) {
    const std::size_t width = std::size_t(tck_datatype_size(type));
    std::vector<double> out(data.size() / width);
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = detail::decode_track_value(data.data() + i * width, type);
    return out;
}

// Streamlines split at NaN, ended by Inf or by the end of the data
// (MRtrix3 3.0's tcksample writes no Inf after the last NaN).
std::vector<std::vector<float>> split_streamlines(const std::string& path, const std::vector<double>& values) {
    auto bad = [&](const std::string& why) { return Error(Errc::tck_format, path + ": invalid .tsf data: " + why); };
    std::vector<std::vector<float>> out;
    std::vector<float> current;
    for (const double v : values) {
        if (std::isnan(v)) {
            out.push_back(std::move(current));
            current.clear();
        } else if (std::isinf(v)) {
            if (!current.empty()) throw bad("the last streamline has no NaN before the end (Inf)");
            return out;
        } else {
            current.push_back(narrow_to_float(v));
            if (!std::isfinite(current.back())) throw bad("value " + std::to_string(v) + " is not a finite float");
        }
    }
    if (!current.empty()) throw bad("truncated (the last streamline has no NaN after it)");
    return out;
}

}  // namespace

std::vector<std::vector<float>> read_track_scalars(const std::string& path) {
    const TckHeader h = detail::read_track_header(path, "mrtrix track scalars", ".tsf");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(Errc::io, path + ": cannot be read");
    in.seekg(0, std::ios::end);
    const auto size = std::uint64_t(in.tellg());
    std::string data(size - h.data_offset, '\0');  // read_track_header checked the offset against the size
    in.seekg(std::streamoff(h.data_offset));
    if (!in.read(data.data(), std::streamsize(data.size()))) throw Error(Errc::io, path + ": read failed");
    return split_streamlines(path, decode_values(h.datatype, data));
}

}  // namespace fiblet
