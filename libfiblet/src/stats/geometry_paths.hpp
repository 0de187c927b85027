// Internal: the fixed-step shortcut of the symmetric metrics
// (geometry_error.cpp: a point's own two segments, proven nearest) can be
// switched off, so tests can check that it gives the window's results bit
// for bit (the AVX2 loops' switch: core/points_avx2.hpp).
#pragma once

namespace fiblet::detail {

// On by default; per thread (tests switch it around one computation).
bool& geometry_shortcut_enabled();

}  // namespace fiblet::detail
