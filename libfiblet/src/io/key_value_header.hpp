// Internal: the text header MRtrix3 puts before binary data, in .tck
// streamline files and .mif images alike: a magic first line, "key: value"
// lines, and "END". A line without ':' continues the previous value (as
// MRtrix and nibabel read it).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fiblet/error.hpp"

namespace fiblet::detail {

struct KeyValueEntry {
    std::string key, value;  // trimmed; continuation lines joined with '\n'
    std::size_t line = 0;    // line number of the key (1: the magic line)
    bool continued = false;  // a continuation line was joined to it
};

struct KeyValueHeader {
    std::vector<KeyValueEntry> entries;  // in file order
    std::uint64_t end = 0;               // byte offset just past the END line
    std::uint64_t file_size = 0;

    // Every value of a key (repeated keys such as "transform" keep their order).
    std::vector<std::string> all(std::string_view key) const;
    // The first value of a key; "" when absent.
    std::string one(std::string_view key) const;
};

// Reads the header of `path`, whose first line must be `magic`, in growing
// blocks (at most 16 MiB of header). Errors are Error{code} "PATH: invalid
// <what> header: ..." (a malformed line is reported only once END is found:
// without END, that is the simpler diagnosis), or Error{io}.
KeyValueHeader read_key_value_header(const std::string& path, std::string_view magic, Errc code,
                                     std::string_view what);

// Without the spaces and tabs MRtrix trims (not NUL: a key may hold one).
std::string_view trim_header_text(std::string_view s);

}  // namespace fiblet::detail
