// Internal: whether any of a block's decoded points lies in a region (the
// selection's point tests, select.cpp): Region::contains for every point,
// the region's shape chosen once, eight points at a time.
#pragma once

#include <cstdint>
#include <vector>

#include "fiblet/select.hpp"

namespace fiblet::detail {

// Points p[3k], p[3k + 1], p[3k + 2], k < n (decoded xyz).
bool any_point_in(const Region& r, const float* p, std::uint32_t n);
// In any of the regions.
bool any_point_in(const std::vector<Region>& regions, const float* p, std::uint32_t n);

}  // namespace fiblet::detail
