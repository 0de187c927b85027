// Internal: where a block's points lie, from block headers alone (no
// decoding): a capsule, the points within `radius` of the segment a-b, and
// whether it may meet a region. The selection tests every candidate
// block's capsule; many at a time, sphere regions in AVX2 vectors.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/default_init_allocator.hpp"
#include "fiblet/select.hpp"
#include "fiblet/view.hpp"

namespace fiblet::detail {

// The block's view sphere (view.hpp: a = b = its first point, radius at
// least the length P of its path) holds its points. When the next block of
// the fiber is at hand and the index bounds the jump from a block's last
// point to the next block's first (`join`), every point p of the block also
// has |p - a| + |p - b| <= P + join with a, b the two first points: an
// ellipsoid, which lies in the capsule of radius sqrt((P + join)^2 -
// |ab|^2) / 2 around a-b. Blocks of smooth fibers are nearly straight, so
// that capsule is thin.
struct BlockBound {
    Vec3f a, b;
    float radius;
};

// `s` is the block's view sphere, `next` the next block's (its centre is
// that block's first point), or null.
BlockBound block_bound(const Sphere& s, const Sphere* next, float join);

// Whether a block within `c` may have a point in region `r`: false only
// when none can, so that the block need not be decoded to be tested.
bool bound_may_meet(const Region& r, const BlockBound& c);

// out[k] = sphere_intersects_frustum(f, spheres[k]) (0 or 1), k < n, four
// spheres at a time: the same float operations in the same order.
void spheres_in_frustum(const Frustum& f, const Sphere* spheres, std::size_t n, std::uint8_t* out);

// The bounds of many blocks, as columns for the vector loops.
class BlockBounds {
public:
    // Bound i = block_bound(spheres[at[i]], next[i] != SIZE_MAX ? &spheres[next[i]] : nullptr, join), i < n.
    void compute(const Sphere* spheres, const std::size_t* at, const std::size_t* next, std::size_t n, float join);
    std::size_t size() const { return n_; }
    BlockBound operator[](std::size_t i) const {
        return {{ax_[i], ay_[i], az_[i]}, {bx_[i], by_[i], bz_[i]}, radius_[i]};
    }
    // out[i] = bound_may_meet(r, (*this)[i]) (0 or 1), sphere regions in vectors.
    void may_meet(const Region& r, std::uint8_t* out) const;

private:
    UninitializedVector<float> ax_, ay_, az_, bx_, by_, bz_, radius_;
    std::size_t n_ = 0;
    void set(std::size_t i, const BlockBound& c);
};

}  // namespace fiblet::detail
