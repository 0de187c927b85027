// Internal: the fixed-step shortcut of the symmetric metrics
// (geometry_error.cpp, own_segments_are_nearest) can be switched off, so
// tests can check that it gives the full window's results bit for bit.
#pragma once

namespace fiblet::detail {

// On by default; per thread (tests switch it around one computation).
bool& geometry_shortcut_enabled();

}  // namespace fiblet::detail
