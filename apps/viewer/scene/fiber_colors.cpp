#include "scene/fiber_colors.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/streamline_field.hpp"
#include "scene/gpu_scene.hpp"
#include "scene/point_values.hpp"

namespace fiblet::viewer {

namespace {

// The whitespace-separated tokens of a text file, '#' lines skipped.
std::vector<std::string> tokens_of(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw Error(Errc::io, path + ": cannot be read");
    std::vector<std::string> out;
    std::string line, token;
    while (std::getline(in, line)) {
        const std::size_t first = line.find_first_not_of(" \t\r");
        if (first == std::string::npos || line[first] == '#') continue;
        std::istringstream words(line);
        while (words >> token) out.push_back(token);
    }
    return out;
}

void check_count(const std::string& path, std::size_t got, std::uint64_t fibers, const char* what) {
    if (got != fibers)
        throw Error(Errc::invalid_input, path + ": " + std::to_string(got) + " " + what + " for " +
                                             std::to_string(fibers) + " streamlines (one per streamline, in file order)");
}

}  // namespace

std::vector<Rgb> read_fiber_colors(const std::string& path, std::uint64_t fibers) {
    const std::vector<std::string> tokens = tokens_of(path);
    check_count(path, tokens.size(), fibers, "colours");
    std::vector<Rgb> out;
    out.reserve(tokens.size());
    for (const std::string& t : tokens) {
        char* end = nullptr;
        const unsigned long v = std::strtoul(t.c_str(), &end, 16);
        if (t.size() != 6 || *end != '\0')
            throw Error(Errc::invalid_input, path + ": '" + t + "' is not a colour RRGGBB");
        out.push_back({float((v >> 16) & 255) / 255.0f, float((v >> 8) & 255) / 255.0f, float(v & 255) / 255.0f});
    }
    return out;
}

std::vector<float> read_fiber_values(const std::string& path, std::uint64_t fibers) {
    const std::vector<std::string> tokens = tokens_of(path);
    check_count(path, tokens.size(), fibers, "values");
    std::vector<float> out;
    out.reserve(tokens.size());
    for (const std::string& t : tokens) {
        char* end = nullptr;
        const float v = std::strtof(t.c_str(), &end);
        if (t.empty() || *end != '\0' || !std::isfinite(v))
            throw Error(Errc::invalid_input, path + ": '" + t + "' is not a finite number");
        out.push_back(v);
    }
    return out;
}

Rgb viridis(float t) {
    static constexpr Rgb kTable[9] = {{0.267f, 0.005f, 0.329f}, {0.279f, 0.175f, 0.483f}, {0.230f, 0.322f, 0.546f},
                                      {0.173f, 0.449f, 0.558f}, {0.128f, 0.567f, 0.551f}, {0.153f, 0.680f, 0.504f},
                                      {0.363f, 0.786f, 0.388f}, {0.678f, 0.864f, 0.190f}, {0.993f, 0.906f, 0.144f}};
    const float x = std::clamp(std::isfinite(t) ? t : 0.0f, 0.0f, 1.0f) * 8.0f;
    const int i = std::min(int(x), 7);
    const float f = x - float(i);
    Rgb c;
    for (int k = 0; k < 3; ++k) c[std::size_t(k)] = kTable[i][std::size_t(k)] + f * (kTable[i + 1][std::size_t(k)] - kTable[i][std::size_t(k)]);
    return c;
}

std::vector<Rgb> colors_from_values(const std::vector<float>& values, std::optional<std::array<float, 2>> range) {
    float low = 0, high = 1;
    if (range) {
        low = (*range)[0], high = (*range)[1];
    } else if (!values.empty()) {
        const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
        low = *lo, high = *hi;
    }
    std::vector<Rgb> out;
    out.reserve(values.size());
    for (const float v : values) out.push_back(viridis(high > low ? (v - low) / (high - low) : 0.5f));
    return out;
}

std::vector<float> fiber_values_from_data(const FftFile& file, const std::string& name) {
    std::string available;
    for (const StreamlineField& f : file.streamline_fields()) {
        if (f.scope() != FieldScope::streamline) continue;
        if (f.name != name) {
            available += (available.empty() ? "" : ", ") + f.name;
            continue;
        }
        if (f.components != 1 || f.rows() != file.header().fibers)
            throw Error(Errc::invalid_input, file.path() + ": " + name + " holds " + std::to_string(f.components) +
                                                 " values per streamline (one is needed for a colour map)");
        std::vector<float> out(f.rows());
        for (std::uint64_t r = 0; r < f.rows(); ++r) {
            out[r] = narrow_to_float(f.at(r, 0));
            if (!std::isfinite(out[r]))
                throw Error(Errc::invalid_input, file.path() + ": " + name + " of streamline " + std::to_string(r) +
                                                     " is not a finite number");
        }
        return out;
    }
    throw Error(Errc::invalid_argument, file.path() + " carries no per-streamline data " + name + " (" +
                                            (available.empty() ? "it has none" : "it has: " + available) + ")");
}

bool is_data_field_name(const std::string& values) { return values.rfind("dps/", 0) == 0 && values.size() > 4; }

std::vector<float> read_fiber_value_source(const std::string& source, const FftFile& file) {
    const bool from_data = is_data_field_name(source) && !std::filesystem::exists(source);
    return from_data ? fiber_values_from_data(file, source) : read_fiber_values(source, file.header().fibers);
}

void load_fiber_colors(const FiberColorSource& source, const FftFile& file, GpuScene& scene) {
    if (!source.colors_path.empty()) {
        scene.set_fiber_colors(read_fiber_colors(source.colors_path, scene.file_fiber_count()));
    } else if (!source.values_path.empty()) {
        scene.set_fiber_colors(colors_from_values(read_fiber_value_source(source.values_path, file), source.value_range));
    }
    if (!source.point_values_path.empty())
        scene.set_point_values(read_point_value_source(source.point_values_path, file, scene.file_fiber_point_counts()));
}

}  // namespace fiblet::viewer
