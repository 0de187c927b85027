// Internal: the header MRtrix3 writes before track data, .tck streamlines
// ("mrtrix tracks") and .tsf track scalars ("mrtrix track scalars") alike:
// key: value lines, a datatype and "file: . OFFSET".
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "fiblet/tck.hpp"

namespace fiblet::detail {

// `magic` is the first line; `what` names the file kind in errors
// (Error{tck_format}, Error{unsupported} for a datatype, Error{io}).
TckHeader read_track_header(const std::string& path, std::string_view magic, std::string_view what);

// One value of a track file's data section in datatype `t` (the tests and
// users run on little-endian hosts; float32 converts to double exactly).
inline double decode_track_value(const char* p, TckDataType t) {
    const bool swap = t == TckDataType::float32be || t == TckDataType::float64be;
    if (tck_datatype_size(t) == 4) {
        std::uint32_t u;
        std::memcpy(&u, p, 4);
        if (swap) u = __builtin_bswap32(u);
        float f;
        std::memcpy(&f, &u, 4);
        return f;
    }
    std::uint64_t u;
    std::memcpy(&u, p, 8);
    if (swap) u = __builtin_bswap64(u);
    double d;
    std::memcpy(&d, &u, 8);
    return d;
}

}  // namespace fiblet::detail
