// Region-of-interest selection of decoded streamlines, with MRtrix3 tckedit
// semantics: a fiber is kept if it has a point inside every include region
// and no point inside any exclude region.
//
// This filters points that were already decoded; the library's block-level
// selection (issue "Skip what a scene doesn't need") will replace it so that
// rejected blocks are never decoded, with the same result.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "fiblet/decode.hpp"

namespace fiblet::python {

struct Region {
    enum class Shape { sphere, box } shape = Shape::sphere;
    std::array<double, 3> a{};  // sphere: centre; box: min corner (mm)
    std::array<double, 3> b{};  // sphere: b[0] = radius; box: max corner (mm)
    bool exclude = false;

    bool contains(const float* p) const;
};

// Fibers in the TRX layout, wherever their memory lives: fiber i is the
// points [offsets[i], offsets[i+1]) of xyz (3 floats each).
struct FibersView {
    const float* xyz;
    std::span<const std::uint64_t> offsets;
    std::uint64_t size() const { return offsets.size() - 1; }
};
inline FibersView view_of(const Streamlines& s) { return {s.xyz.data(), s.offsets}; }

// Indices (into `s`) of the fibers the regions keep, in order.
std::vector<std::uint64_t> fibers_kept(FibersView s, const std::vector<Region>& regions);

// The fibers of `s` listed in `keep` (in that order), as a new Streamlines.
Streamlines gather_fibers(FibersView s, const std::vector<std::uint64_t>& keep);

}  // namespace fiblet::python
