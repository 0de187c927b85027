// Test images: a source image written here in the simplest MRtrix form
// (.mif, Float32LE, +0,+1,+2 layout), which MRtrix3's mrconvert then turns
// into the files the reader is tested on (.nii, .nii.gz, other .mif layouts
// and datatypes): files written by another tool.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "fiblet/image.hpp"
#include "test_util.hpp"

namespace fiblet::test {

struct SourceImage {
    std::vector<std::int64_t> dims;          // 3 or 4 axes
    std::array<double, 3> vox{1, 1, 1};
    Affine3x4 transform{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};  // unit axes + translation (mm)
    std::vector<float> values;               // x fastest

    std::int64_t count() const {
        std::int64_t n = 1;
        for (auto d : dims) n *= d;
        return n;
    }
    // Voxel -> world as MRtrix defines it: transform * diag(vox).
    Affine3x4 voxel_to_world() const {
        Affine3x4 m = transform;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) m[r][c] *= vox[c];
        return m;
    }
    void fill(const std::function<float(std::int64_t, std::int64_t, std::int64_t, std::int64_t)>& f) {
        values.resize(std::size_t(count()));
        const std::int64_t nv = dims.size() > 3 ? dims[3] : 1;
        std::size_t at = 0;
        for (std::int64_t v = 0; v < nv; ++v)
            for (std::int64_t k = 0; k < dims[2]; ++k)
                for (std::int64_t j = 0; j < dims[1]; ++j)
                    for (std::int64_t i = 0; i < dims[0]; ++i) values[at++] = f(i, j, k, v);
    }
    void write_mif(const std::string& path) const {
        auto list = [](const auto& v, std::size_t n) {
            std::string s;
            for (std::size_t i = 0; i < n; ++i) s += (i ? "," : "") + fmt_double(double(v[i]));
            return s;
        };
        std::string layout;
        for (std::size_t a = 0; a < dims.size(); ++a) layout += (a ? ",+" : "+") + std::to_string(a);
        std::string h = "mrtrix image\ndim: " + list(dims, dims.size()) + "\nvox: " + list(vox, 3) +
                        (dims.size() > 3 ? ",1" : "") + "\nlayout: " + layout + "\ndatatype: Float32LE\n";
        for (const auto& row : transform) h += "transform: " + list(row, 4) + "\n";
        h += "file: . 1024\nEND\n";
        h.resize(1024, ' ');
        std::string bytes = h;
        bytes.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
        write_file(path, bytes);
    }
    static std::string fmt_double(double x) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.17g", x);
        return buf;
    }
};

inline bool have_mrtrix() { return run_command("mrconvert -version >/dev/null 2>&1").status == 0; }

// mrconvert SRC DST OPTIONS (quiet, overwriting); true on success.
inline bool mrconvert(const std::string& src, const std::string& dst, const std::string& options = "") {
    return run_command("mrconvert -quiet -force " + src + " " + dst + " " + options + " 2>&1").status == 0;
}

}  // namespace fiblet::test
