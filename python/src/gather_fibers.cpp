#include "roi_filter.hpp"

#include <algorithm>
#include <cstring>

namespace fiblet::python {

bool Region::contains(const float* p) const {
    if (shape == Shape::sphere) {
        const double dx = p[0] - a[0], dy = p[1] - a[1], dz = p[2] - a[2];
        return dx * dx + dy * dy + dz * dz <= b[0] * b[0];
    }
    for (int k = 0; k < 3; ++k)
        if (!(p[k] >= a[k] && p[k] <= b[k])) return false;
    return true;
}

std::vector<std::uint64_t> fibers_kept(FibersView s, const std::vector<Region>& regions) {
    std::vector<std::uint64_t> keep;
    for (std::uint64_t f = 0; f < s.size(); ++f) {
        const float* begin = s.xyz + 3 * s.offsets[f];
        const float* end = s.xyz + 3 * s.offsets[f + 1];
        bool kept = true;
        for (const Region& r : regions) {
            bool hit = false;
            for (const float* p = begin; p != end && !hit; p += 3) hit = r.contains(p);
            if (hit == r.exclude) {
                kept = false;
                break;
            }
        }
        if (kept) keep.push_back(f);
    }
    return keep;
}

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
