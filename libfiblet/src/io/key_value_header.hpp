// Internal: the text header MRtrix3 puts before binary data (.mif images;
// .tck streamlines have the same form): a magic first line, "key: value"
// lines, and "END". A line without ':' continues the previous value.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fiblet/error.hpp"

namespace fiblet::detail {

struct KeyValueHeader {
    std::vector<std::pair<std::string, std::string>> entries;  // in file order, keys and values trimmed
    std::uint64_t end = 0;        // byte offset just past the END line
    std::uint64_t file_size = 0;

    // Every value of a key (repeated keys such as "transform" keep their order).
    std::vector<std::string> all(std::string_view key) const;
    // The value of a key that must appear at most once; "" when absent.
    std::string one(std::string_view key) const;
};

// Reads the header of `path` whose first line must be `magic`; errors are
// Error{code} "PATH: invalid <what> header: ...", or Error{io}.
KeyValueHeader read_key_value_header(const std::string& path, std::string_view magic, Errc code,
                                     std::string_view what);

}  // namespace fiblet::detail
