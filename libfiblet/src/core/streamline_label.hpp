// Internal: how messages name a streamline. One convention everywhere: the
// 0-based position in the file, as `extract --fibers` and the .fft fiber IDs
// count (a message and the option that selects that streamline agree).
#pragma once

#include <cstdint>
#include <string>

namespace fiblet::detail {

inline std::string streamline_label(std::uint64_t index) {
    return "streamline " + std::to_string(index) + " (0-based)";
}

}  // namespace fiblet::detail
