// Four lanes in GCC's portable vector types: an SSE register on any
// x86-64, NEON on ARM, so loops over them need no dispatch and no -m flag.
// Arithmetic mixes lanes and scalars (a scalar is broadcast); comparisons
// give -1 (true) or 0 a lane; each lane's float operation is IEEE's, as in
// scalar code (libfiblet builds with -ffp-contract=off).
#pragma once

#include <cstdint>

namespace fiblet::detail {

using Floats = float __attribute__((vector_size(16)));
using Ints = std::int32_t __attribute__((vector_size(16)));
using Words = std::uint64_t __attribute__((vector_size(16)));

}  // namespace fiblet::detail
