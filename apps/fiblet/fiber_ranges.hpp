// --fibers, one syntax for every subcommand: IDs and inclusive ranges,
// "0,5,10-20" (0-based); a range may also be written FIRST:LAST, as MRtrix3
// writes number sequences.
#pragma once

#include <string>
#include <vector>

#include "fiblet/select.hpp"

namespace fiblet::cli {

// Throws Error(Errc::invalid_argument) naming `option` and the bad item.
std::vector<FiberRange> parse_fiber_ranges(const std::string& option, const std::string& text);

}  // namespace fiblet::cli
