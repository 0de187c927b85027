// Internal: validation of a query's values before anything is read.
#pragma once

#include <cstddef>

#include "fiblet/select.hpp"

namespace fiblet::detail {

// Fibers mode tracks the include regions a fiber has met in one 64-bit mask.
inline constexpr std::size_t kMaxIncludeRegions = 64;

// Throws Error{invalid_argument} naming the first bad value.
void check_query(const Query& q);

}  // namespace fiblet::detail
