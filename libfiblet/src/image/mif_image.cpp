// MRtrix3 .mif images (and .mih headers with a separate data file): the
// key-value header (dim, vox, layout, datatype, transform, scaling, file)
// and the data in any layout and real datatype MRtrix writes.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "fiblet/error.hpp"
#include "image/image_readers.hpp"
#include "io/key_value_header.hpp"
#include "io/regular_input.hpp"

namespace fiblet::detail {
namespace {

enum class Kind { bit, i8, u8, i16, u16, i32, u32, i64, u64, f32, f64 };
struct DataType {
    Kind kind;
    bool big_endian = false;
};

[[noreturn]] void bad(const std::string& path, const std::string& what) {
    throw Error(Errc::image_format, path + ": invalid .mif image: " + what);
}

std::vector<double> numbers(const std::string& path, const std::string& key, const std::string& text) {
    std::vector<double> v;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        std::size_t used = 0;
        try {
            v.push_back(std::stod(item, &used));
        } catch (const std::exception&) {
            used = 0;
        }
        while (used < item.size() && std::isspace(static_cast<unsigned char>(item[used]))) ++used;
        if (used == 0 || used != item.size()) bad(path, "\"" + key + ": " + text + "\" is not a list of numbers");
    }
    return v;
}

DataType parse_datatype(const std::string& path, std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    DataType t{Kind::u8};
    if (s.size() > 2 && (s.ends_with("le") || s.ends_with("be"))) {
        t.big_endian = s.ends_with("be");
        s.resize(s.size() - 2);
    }
    static const std::pair<const char*, Kind> names[] = {
        {"bit", Kind::bit},     {"int8", Kind::i8},     {"uint8", Kind::u8},     {"int16", Kind::i16},
        {"uint16", Kind::u16},  {"int32", Kind::i32},   {"uint32", Kind::u32},   {"int64", Kind::i64},
        {"uint64", Kind::u64},  {"float32", Kind::f32}, {"float64", Kind::f64}};
    for (const auto& [name, kind] : names)
        if (s == name) return t.kind = kind, t;
    if (s.starts_with("cfloat"))
        throw Error(Errc::unsupported, path + ": complex .mif images are not supported (real-valued voxels only)");
    bad(path, "unknown datatype \"" + s + "\"");
}

std::size_t bytes_of(Kind k) {
    switch (k) {
        case Kind::bit: return 0;
        case Kind::i8: case Kind::u8: return 1;
        case Kind::i16: case Kind::u16: return 2;
        case Kind::i32: case Kind::u32: case Kind::f32: return 4;
        case Kind::i64: case Kind::u64: case Kind::f64: return 8;
    }
    return 0;
}

template <class T>
double fetch(const std::uint8_t* p, bool big_endian) {
    std::array<std::uint8_t, sizeof(T)> b;
    std::memcpy(b.data(), p, sizeof(T));
    if (big_endian != (std::endian::native == std::endian::big)) std::reverse(b.begin(), b.end());
    T v;
    std::memcpy(&v, b.data(), sizeof(T));
    return double(v);
}

// Value number `i` of the data (in storage order).
double value_at(const std::vector<std::uint8_t>& d, std::size_t i, DataType t) {
    const std::size_t w = bytes_of(t.kind);
    const std::uint8_t* p = d.data() + i * w;
    switch (t.kind) {
        case Kind::bit: return (d[i / 8] >> (7 - i % 8)) & 1;  // most significant bit first, as MRtrix packs
        case Kind::i8: return double(std::int8_t(*p));
        case Kind::u8: return double(*p);
        case Kind::i16: return fetch<std::int16_t>(p, t.big_endian);
        case Kind::u16: return fetch<std::uint16_t>(p, t.big_endian);
        case Kind::i32: return fetch<std::int32_t>(p, t.big_endian);
        case Kind::u32: return fetch<std::uint32_t>(p, t.big_endian);
        case Kind::i64: return fetch<std::int64_t>(p, t.big_endian);
        case Kind::u64: return fetch<std::uint64_t>(p, t.big_endian);
        case Kind::f32: return fetch<float>(p, t.big_endian);
        case Kind::f64: return fetch<double>(p, t.big_endian);
    }
    return 0;
}

// "layout: +0,-1,+2": for each axis, its rank in stride order and whether
// it is stored backwards (MRtrix's parse_axes).
std::vector<std::int64_t> parse_layout(const std::string& path, const std::string& text, std::size_t ndim) {
    std::vector<std::int64_t> signed_rank;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        const bool negative = !item.empty() && item[0] == '-';
        if (!item.empty() && (item[0] == '+' || item[0] == '-')) item.erase(0, 1);
        if (item.empty() || item.find_first_not_of("0123456789") != std::string::npos || item.size() > 3)
            bad(path, "malformed layout \"" + text + "\"");
        const std::int64_t rank = std::stoll(item) + 1;
        signed_rank.push_back(negative ? -rank : rank);
    }
    if (signed_rank.size() != ndim) bad(path, "layout \"" + text + "\" does not have one entry per axis");
    for (std::size_t a = 0; a < ndim; ++a) {
        if (std::abs(signed_rank[a]) > std::int64_t(ndim)) bad(path, "layout \"" + text + "\" has an axis out of range");
        for (std::size_t b = 0; b < a; ++b)
            if (std::abs(signed_rank[a]) == std::abs(signed_rank[b])) bad(path, "layout \"" + text + "\" repeats an axis");
    }
    return signed_rank;
}

// "file: . OFFSET" (data after the header) or "file: NAME OFFSET" (.mih).
std::pair<std::string, std::uint64_t> data_file(const std::string& path, const std::string& entry) {
    std::stringstream ss(entry);
    std::string name;
    std::uint64_t offset = 0;
    if (!(ss >> name)) bad(path, "missing \"file:\" entry");
    if (!(ss >> offset)) offset = 0;
    if (name == ".") return {path, offset};
    return {(std::filesystem::path(path).parent_path() / name).string(), offset};
}

std::vector<std::uint8_t> read_bytes(const std::string& path, std::uint64_t offset, std::uint64_t n) {
    require_regular_input(path);  // a .mih's file: may name any path
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
    in.seekg(0, std::ios::end);
    const auto size = std::uint64_t(in.tellg());
    if (offset > size || size - offset < n)
        throw Error(Errc::image_format, path + ": image data truncated (" + std::to_string(n) + " bytes expected at offset " +
                                            std::to_string(offset) + ", the file has " + std::to_string(size) + ")");
    std::vector<std::uint8_t> bytes(n);
    in.seekg(std::streamoff(offset));
    if (!in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(n)))
        throw Error(Errc::io, path + ": read failed: " + std::strerror(errno));
    return bytes;
}

}  // namespace

Image read_mif(const std::string& path, VoxelOutput out) {
    const KeyValueHeader kv = read_key_value_header(path, "mrtrix image", Errc::image_format, ".mif");
    Image img;
    img.path = path;
    const std::string dim_text = kv.one("dim"), vox_text = kv.one("vox");
    if (dim_text.empty()) bad(path, "missing \"dim:\"");
    if (vox_text.empty()) bad(path, "missing \"vox:\"");
    for (const double d : numbers(path, "dim", dim_text)) {
        if (!(d >= 1 && d < 9.0e15 && d == std::floor(d))) bad(path, "dimensions \"" + dim_text + "\" are not positive integers");
        img.dims.push_back(std::int64_t(d));
    }
    const std::size_t ndim = img.dims.size();
    while (img.dims.size() < 3) img.dims.push_back(1);
    const std::vector<double> vox = numbers(path, "vox", vox_text);
    if (vox.size() < std::min<std::size_t>(3, ndim)) bad(path, "too few voxel sizes in \"vox: " + vox_text + "\"");
    for (std::size_t a = 0; a < 3; ++a) {
        const double s = a < vox.size() && a < ndim ? vox[a] : 1.0;
        if (!(std::isfinite(s) && s > 0)) bad(path, "voxel sizes \"" + vox_text + "\" must be positive");
        img.spacing[a] = s;
    }
    const std::string dtype_text = kv.one("datatype"), layout_text = kv.one("layout");
    if (dtype_text.empty()) bad(path, "missing \"datatype:\"");
    if (layout_text.empty()) bad(path, "missing \"layout:\"");
    const DataType dtype = parse_datatype(path, dtype_text);
    const std::vector<std::int64_t> layout = parse_layout(path, layout_text, ndim);

    const auto rows = kv.all("transform");
    Affine3x4 m{};
    if (rows.empty()) {
        m = centred_transform(img);
    } else {
        if (rows.size() < 3) bad(path, "\"transform:\" needs three rows");
        for (int r = 0; r < 3; ++r) {
            const auto row = numbers(path, "transform", rows[r]);
            if (row.size() != 4) bad(path, "a \"transform:\" row needs four numbers");
            for (int c = 0; c < 4; ++c) m[r][c] = row[c];
        }
    }
    img.voxel_to_world = voxel_to_world(m, img.spacing);
    check_transform(img);
    if (!out.values && !out.counts) return img;

    // "scaling: offset,scale" applies to integer data only, as MRtrix 3.0
    // reads it (float data is used as stored; tests/image_test.cpp).
    double offset = 0, scale = 1;
    const bool integer = dtype.kind != Kind::f32 && dtype.kind != Kind::f64;
    if (const std::string s = kv.one("scaling"); !s.empty() && integer) {
        const auto v = numbers(path, "scaling", s);
        if (v.size() != 2) bad(path, "\"scaling:\" needs offset,scale");
        offset = v[0], scale = v[1];
    }

    // Storage order: axes by rank; a negative axis runs backwards.
    const std::size_t n = voxel_count(path, img.dims);
    std::vector<std::size_t> stride(ndim);
    {
        std::vector<std::size_t> by_rank(ndim);
        for (std::size_t a = 0; a < ndim; ++a) by_rank[std::size_t(std::abs(layout[a]) - 1)] = a;
        std::size_t s = 1;
        for (const std::size_t a : by_rank) stride[a] = s, s *= std::size_t(img.dims[a]);
    }
    const std::size_t width = bytes_of(dtype.kind);
    const std::uint64_t data_bytes = width ? n * width : (n + 7) / 8;
    const auto [file, data_offset] = data_file(path, kv.one("file"));
    const std::vector<std::uint8_t> bytes = read_bytes(file, data_offset, data_bytes);

    // Output order (x fastest, the volumes last): a mask stops after the first volume.
    const std::size_t wanted = out.values ? n : std::size_t(img.dims[0] * img.dims[1] * img.dims[2]);
    out.grow_to(wanted);
    std::vector<std::int64_t> idx(ndim, 0);
    for (std::size_t voxel = 0; voxel < wanted; ++voxel) {
        std::size_t at = 0;
        for (std::size_t a = 0; a < ndim; ++a)
            at += stride[a] * std::size_t(layout[a] < 0 ? img.dims[a] - 1 - idx[a] : idx[a]);
        out.put(voxel, float(offset + scale * value_at(bytes, at, dtype)));
        for (std::size_t a = 0; a < ndim && ++idx[a] == img.dims[a]; ++a) idx[a] = 0;
    }
    return img;
}

}  // namespace fiblet::detail
