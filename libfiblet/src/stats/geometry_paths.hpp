// Internal: the faster paths of the symmetric metrics (geometry_error.cpp)
// can be switched off, so tests can check that they give the reference
// paths' results bit for bit: the fixed-step shortcut (a point's own two
// segments, proven nearest) against the window, and the AVX2 loops against
// the scalar ones (which machines without AVX2 run).
#pragma once

namespace fiblet::detail {

// On by default; per thread (tests switch them around one computation).
bool& geometry_shortcut_enabled();
bool& geometry_vectors_enabled();

}  // namespace fiblet::detail
