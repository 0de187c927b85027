#include "scene/point_values.hpp"

#include <algorithm>
#include <bit>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/streamline_field.hpp"

namespace fiblet::viewer {

namespace {

struct TsfHeader {
    std::string datatype;
    std::uint64_t offset = 0;
};

std::string trimmed(const std::string& s) {
    const std::size_t a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
    return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// The key: value lines up to END (mrtrix's header format).
TsfHeader parse_header(const std::string& path, const std::string& bytes) {
    auto bad = [&](const std::string& why) { return Error(Errc::invalid_input, path + ": " + why); };
    std::size_t pos = 0;
    bool first = true, ended = false;
    TsfHeader h;
    bool has_file = false;
    while (pos < bytes.size() && !ended) {
        std::size_t eol = bytes.find('\n', pos);
        if (eol == std::string::npos) eol = bytes.size();
        const std::string line = trimmed(bytes.substr(pos, eol - pos));
        pos = eol + 1;
        if (first) {
            if (line != "mrtrix track scalars") throw bad("not a track scalar file (no 'mrtrix track scalars' line)");
            first = false;
            continue;
        }
        if (line == "END") {
            ended = true;
            break;
        }
        const std::size_t colon = line.find(':');
        if (colon == std::string::npos) continue;
        const std::string key = trimmed(line.substr(0, colon)), value = trimmed(line.substr(colon + 1));
        if (key == "datatype") h.datatype = value;
        if (key == "file") {
            char dot = 0;
            unsigned long long off = 0;
            if (std::sscanf(value.c_str(), "%c %llu", &dot, &off) != 2 || dot != '.')
                throw bad("'file: " + value + "' is not '. OFFSET' (data in the same file)");
            h.offset = off, has_file = true;
        }
    }
    if (!ended) throw bad("the header has no END line");
    if (!has_file) throw bad("the header has no 'file: . OFFSET' line");
    if (h.offset < pos || h.offset > bytes.size()) throw bad("the data offset " + std::to_string(h.offset) + " is outside the file");
    return h;
}

// The values from `data` as `datatype` says (Float32/64, LE/BE).
std::vector<double> decode_values(const std::string& path, const std::string& datatype, const char* data, std::size_t size) {
    const bool f32 = datatype.rfind("Float32", 0) == 0, f64 = datatype.rfind("Float64", 0) == 0;
    const std::string order = datatype.size() > 7 ? datatype.substr(7) : "";
    if ((!f32 && !f64) || (order != "LE" && order != "BE"))
        throw Error(Errc::invalid_input, path + ": datatype '" + datatype + "' is not Float32LE, Float32BE, Float64LE or Float64BE");
    const std::size_t width = f32 ? 4 : 8;
    const bool swap = (order == "LE") != (std::endian::native == std::endian::little);
    std::vector<double> out(size / width);
    for (std::size_t i = 0; i < out.size(); ++i) {
        unsigned char b[8];
        std::memcpy(b, data + i * width, width);
        if (swap) std::reverse(b, b + width);
        if (f32) {
            float v;
            std::memcpy(&v, b, 4);
            out[i] = v;
        } else {
            std::memcpy(&out[i], b, 8);
        }
    }
    return out;
}

// Streamlines split at NaN, ended by Inf.
std::vector<std::vector<float>> split_streamlines(const std::string& path, const std::vector<double>& values) {
    std::vector<std::vector<float>> out;
    std::vector<float> current;
    for (const double v : values) {
        if (std::isnan(v)) {
            out.push_back(std::move(current));
            current.clear();
        } else if (std::isinf(v)) {
            if (!current.empty()) throw Error(Errc::invalid_input, path + ": the last streamline has no NaN before the end (Inf)");
            return out;
        } else {
            current.push_back(narrow_to_float(v));
            if (!std::isfinite(current.back()))
                throw Error(Errc::invalid_input, path + ": value " + std::to_string(v) + " is not a finite float");
        }
    }
    throw Error(Errc::invalid_input, path + ": truncated (no Inf after the last streamline)");
}

}  // namespace

std::vector<std::vector<float>> read_track_scalars(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(Errc::io, path + ": cannot be read");
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const TsfHeader h = parse_header(path, bytes);
    const std::vector<double> values = decode_values(path, h.datatype, bytes.data() + h.offset, bytes.size() - h.offset);
    return split_streamlines(path, values);
}

std::vector<float> read_point_values(const std::string& path, const std::vector<std::uint32_t>& fiber_points,
                                     bool resampled) {
    const std::vector<std::vector<float>> tracks = read_track_scalars(path);
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
