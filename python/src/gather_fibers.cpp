#include "gather_fibers.hpp"

#include <algorithm>

namespace fiblet::python {

Streamlines gather_fibers(FibersView s, const std::vector<std::uint64_t>& keep) {
    Streamlines out;
    out.offsets.reserve(keep.size() + 1);
    std::uint64_t points = 0;
    for (std::uint64_t f : keep) out.offsets.push_back(points += s.offsets[f + 1] - s.offsets[f]);
    out.xyz.resize(3 * points);
    for (std::size_t i = 0; i < keep.size(); ++i) {
        const std::uint64_t f = keep[i];
        std::copy(s.xyz + 3 * s.offsets[f], s.xyz + 3 * s.offsets[f + 1], out.xyz.begin() + 3 * out.offsets[i]);
    }
    return out;
}

}  // namespace fiblet::python
