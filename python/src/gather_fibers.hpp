// Gathering fibers decoded in several pieces into one Streamlines, in the
// order the caller asked for (fiblet.load(fibers=[...]) in any order).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "fiblet/decode.hpp"

namespace fiblet::python {

// Fibers in the TRX layout, wherever their memory lives: fiber i is the
// points [offsets[i], offsets[i+1]) of xyz (3 floats each).
struct FibersView {
    const float* xyz;
    std::span<const std::uint64_t> offsets;
    std::uint64_t size() const { return offsets.size() - 1; }
};
inline FibersView view_of(const Streamlines& s) { return {s.xyz.data(), s.offsets}; }

// The fibers of `s` listed in `keep` (in that order), as a new Streamlines.
Streamlines gather_fibers(FibersView s, const std::vector<std::uint64_t>& keep);

}  // namespace fiblet::python
