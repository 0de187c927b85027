// Internal: the fixed-step shortcut of the symmetric metrics
// (geometry_error.cpp: a point's own two segments, proven nearest) can be
// switched off, so tests can check that it gives the window's results bit
// for bit (the AVX2 loops' switch: core/points_avx2.hpp).
#pragma once

#include <span>

#include "fiblet/geometry.hpp"

namespace fiblet::detail {

// On by default; per thread (tests switch it around one computation).
bool& geometry_shortcut_enabled();

// Whether the vector loops take the polyline's forward tests as holding
// without computing them (every turn between consecutive segments under 28
// degrees); false without AVX2 loops or under 10 points. For tests: where
// it is true, every pair of segments up to three apart must have a
// non-negative float dot product.
bool forward_tests_skipped(std::span<const Vec3f> line);

}  // namespace fiblet::detail
