// Internal: the view spheres of many blocks in one call, for selections
// that test every candidate block's header (a call per block cost more than
// the arithmetic).
#pragma once

#include <cstddef>
#include <cstdint>

#include "fiblet/fft_format.hpp"
#include "fiblet/view.hpp"

namespace fiblet::detail {

// out[i] = block_bounding_sphere(h, blocks[i]), bit for bit.
void block_spheres(const FftHeader& h, const std::uint8_t* const* blocks, std::size_t n, Sphere* out);

}  // namespace fiblet::detail
