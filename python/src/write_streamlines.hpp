// Writing streamlines from Python to the formats decompress writes (.tck,
// .trk, .trx): fiblet.save() with a name that is not a .fft. Through the
// library's sinks (fiblet/streamline_io.hpp), so the files are written
// atomically and refuse to replace an existing one unless told to.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "fiblet/streamline_io.hpp"

namespace fiblet::python {

// Throws Error{invalid_argument} unless `path` names a .tck, .trk or .trx
// file: open_streamline_sink writes a .tck under any other name.
void require_streamline_output(const std::string& path);

// Fiber i is the points offsets[i] .. offsets[i + 1] - 1 of xyz (3 floats
// each); offsets already checked (from 0 to the point count, not
// decreasing). .trk and .trx get the default space (identity, RAS, 1 mm).
void write_streamlines(const std::string& path, const float* xyz, std::span<const std::int64_t> offsets,
                       const Properties& properties, bool overwrite);

struct Conversion {
    std::uint64_t fibers = 0, points = 0;
    std::size_t fields_dropped = 0;  // data arrays a .tck cannot hold
};

// Reads `input` (.tck, .trk, TRX, by content, as compress does) and writes
// `output` as its extension says, with the source's header properties,
// space and data arrays, as `fiblet decompress` gives them back from a .fft.
Conversion convert_streamlines(const std::string& input, const std::string& output, bool overwrite);

}  // namespace fiblet::python
