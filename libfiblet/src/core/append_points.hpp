// Internal: appending a run of points to a vector at the speed of memcpy.
// Vec3f's members default to 0, so it is not a trivial type and
// std::vector::insert copies it point by point (12 bytes a loop: 2 % of
// compress, the reader's copy of every fiber); a resize (a vectorized
// fill) and one memcpy (Vec3f is trivially copyable) cost a third of that.
#pragma once

#include <cstring>
#include <vector>

#include "fiblet/geometry.hpp"

namespace fiblet::detail {

inline void append_points(std::vector<Vec3f>& out, const Vec3f* first, std::size_t n) {
    if (n == 0) return;
    const std::size_t at = out.size();
    out.resize(at + n);
    std::memcpy(static_cast<void*>(out.data() + at), first, n * sizeof(Vec3f));
}

}  // namespace fiblet::detail
