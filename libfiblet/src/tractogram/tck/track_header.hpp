// Internal: the header MRtrix3 writes before track data, .tck streamlines
// ("mrtrix tracks") and .tsf track scalars ("mrtrix track scalars") alike:
// key: value lines, a datatype and "file: . OFFSET".
#pragma once

#include <string>
#include <string_view>

#include "fiblet/tck.hpp"

namespace fiblet::detail {

// `magic` is the first line; `what` names the file kind in errors
// (Error{tck_format}, Error{unsupported} for a datatype, Error{io}).
TckHeader read_track_header(const std::string& path, std::string_view magic, std::string_view what);

}  // namespace fiblet::detail
