// Parsing the TrackVis header (either byte order), as nibabel reads it.
#include <sys/stat.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>

#include "fiblet/error.hpp"
#include "fiblet/trk.hpp"
#include "tractogram/trk/trk_layout.hpp"

namespace fiblet {
namespace {

using namespace detail::trk;

struct Fields {
    const std::uint8_t* bytes;
    bool swap;
    template <class T>
    T get(std::size_t at) const {
        std::array<std::uint8_t, sizeof(T)> b;
        std::memcpy(b.data(), bytes + at, sizeof(T));
        if (swap) std::reverse(b.begin(), b.end());
        return std::bit_cast<T>(b);
    }
};

[[noreturn]] void bad(const std::string& path, const std::string& what) {
    throw Error(Errc::trk_format, path + ": not a valid TrackVis .trk file: " + what);
}

// nibabel's decode_value_from_name: "name", or "name\0N" for N values; an
// empty name counts 0.
TrkHeader::Named decode_name(const std::uint8_t* p, const std::string& path) {
    std::string s(reinterpret_cast<const char*>(p), kNameBytes);
    while (!s.empty() && s.back() == '\0') s.pop_back();
    if (s.empty()) return {"", 0};
    const auto nul = s.find('\0');
    if (nul == std::string::npos) return {s, 1};
    const std::string count = s.substr(nul + 1);
    // Up to 5 digits: n_scalars and n_properties are int16 (nibabel writes "w\020000").
    if (count.empty() || count.size() > 5 || !std::all_of(count.begin(), count.end(), ::isdigit))
        bad(path, "field name \"" + s.substr(0, nul) + "\" is followed by \"" + count + "\", not a value count");
    return {s.substr(0, nul), std::stoi(count)};
}

std::vector<TrkHeader::Named> decode_names(const std::uint8_t* p, int total, const char* rest, const std::string& path) {
    std::vector<TrkHeader::Named> names;
    int named = 0;
    for (std::size_t i = 0; i < kMaxNames && total > 0; ++i) {
        TrkHeader::Named n = decode_name(p + i * kNameBytes, path);
        if (n.count == 0) continue;
        if (!is_valid_field_name_part(n.name))
            bad(path, "field name \"" + n.name + "\" is not printable UTF-8 without '/', '\\', \".\" or \"..\"");
        for (const auto& earlier : names)
            if (earlier.name == n.name) bad(path, "field name \"" + n.name + "\" appears twice");
        named += n.count;
        names.push_back(std::move(n));
    }
    if (named > total)
        bad(path, "field names count " + std::to_string(named) + " values, the header " + std::to_string(total));
    if (named < total) {
        for (const auto& earlier : names)
            if (earlier.name == rest) bad(path, std::string("a named field is called \"") + rest + "\", the name of the unnamed values");
        names.push_back({rest, total - named});
    }
    return names;
}

}  // namespace

TrkHeader read_trk_header(const std::string& path) {
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
    if (!f) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
    std::array<std::uint8_t, kHeaderSize> raw{};
    const std::size_t got = std::fread(raw.data(), 1, raw.size(), f.get());
    if (got < 5 || std::memcmp(raw.data(), "TRACK", 5) != 0) bad(path, "no \"TRACK\" magic");
    if (got < kHeaderSize) bad(path, "truncated header (" + std::to_string(got) + " of 1000 bytes)");
    TrkHeader h;
    Fields le{raw.data(), false}, be{raw.data(), true};
    h.big_endian = le.get<std::int32_t>(kHdrSize) != 1000;
    const Fields& in = h.big_endian ? be : le;
    if (in.get<std::int32_t>(kHdrSize) != 1000)
        bad(path, "hdr_size is " + std::to_string(le.get<std::int32_t>(kHdrSize)) + " (1000 in either byte order expected)");
    h.version = in.get<std::int32_t>(kVersion);
    if (h.version < 1 || h.version > 2)
        throw Error(Errc::unsupported, path + ": TrackVis .trk version " + std::to_string(h.version) +
                                           " is not supported (fiblet reads versions 1 and 2)");
    for (int k = 0; k < 3; ++k) {
        h.space.dimensions[std::size_t(k)] = in.get<std::int16_t>(kDim + 2 * std::size_t(k));
        h.space.voxel_sizes[std::size_t(k)] = in.get<float>(kVoxelSize + 4 * std::size_t(k));
        h.origin[std::size_t(k)] = in.get<float>(kOrigin + 4 * std::size_t(k));
    }
    for (int k = 0; k < 3; ++k)
        if (h.space.dimensions[std::size_t(k)] < 0)
            bad(path, "dimension " + std::to_string(h.space.dimensions[std::size_t(k)]) + " is negative");
    for (int k = 0; k < 3; ++k)
        if (!(h.space.voxel_sizes[std::size_t(k)] > 0 && std::isfinite(h.space.voxel_sizes[std::size_t(k)])))
            bad(path, "voxel size " + std::to_string(h.space.voxel_sizes[std::size_t(k)]) + " is not positive");
    // Version 1 has no matrix; a 0 at [3][3] means "not recorded": identity (as nibabel).
    if (h.version != 1 && in.get<float>(kVoxToRas + 60) != 0)
        for (std::size_t i = 0; i < 16; ++i) {
            h.space.voxel_to_rasmm[i] = in.get<float>(kVoxToRas + 4 * i);
            if (!std::isfinite(h.space.voxel_to_rasmm[i])) bad(path, "vox_to_ras holds a non-finite number");
        }
    std::string order(reinterpret_cast<const char*>(raw.data() + kVoxelOrder), 4);
    order.resize(std::strlen(order.c_str()));
    h.space.voxel_order = order.empty() ? "LPS" : order;  // TrackVis's default (nibabel too)
    h.n_scalars = in.get<std::int16_t>(kNScalars);
    h.n_properties = in.get<std::int16_t>(kNProperties);
    if (h.n_scalars < 0 || h.n_properties < 0)
        bad(path, "negative n_scalars or n_properties (" + std::to_string(h.n_scalars) + ", " +
                      std::to_string(h.n_properties) + ")");
    h.scalars = decode_names(raw.data() + kScalarNames, h.n_scalars, "scalars", path);
    h.properties = decode_names(raw.data() + kPropertyNames, h.n_properties, "properties", path);
    const std::int32_t count = in.get<std::int32_t>(kNCount);
    if (count < 0) bad(path, "n_count is negative (" + std::to_string(count) + ")");
    h.n_count = std::uint32_t(count);
    try {
        (void)trk_voxmm_to_rasmm(h.space);  // an order or a matrix without clear axes
    } catch (const Error& e) {
        bad(path, e.what());
    }
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0) h.file_bytes = std::uint64_t(st.st_size);
    return h;
}

}  // namespace fiblet
