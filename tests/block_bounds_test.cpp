// detail::BlockBounds (the capsules a selection tests every candidate block
// by, four at a time with AVX2) against block_bound and bound_may_meet, one
// block at a time, and bound_may_meet against points sampled in a capsule.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "scoped_simd_loops.hpp"
#include "select/block_bounds.hpp"

namespace fiblet {
namespace {

using detail::BlockBound;
using detail::BlockBounds;

// Spheres along a wiggly fiber (the next block's centre a block's length
// on, as in a file), some far apart (a jump the index does not describe),
// some of radius 0, some far from the origin.
std::vector<Sphere> fiber_spheres(std::size_t n, std::mt19937& rng) {
    std::normal_distribution<float> step(0, 3);
    std::uniform_real_distribution<float> radius(0, 8);
    std::vector<Sphere> out;
    Vec3f p{12, -30, 4};
    for (std::size_t i = 0; i < n; ++i) {
        if (i % 11 == 5) p = {p.x + 200, p.y, p.z};
        if (i % 17 == 3) p = {p.x + 3e6f, p.y, p.z - 1e6f};
        out.push_back({p, i % 9 == 4 ? 0.0f : radius(rng)});
        p = {p.x + step(rng), p.y + step(rng), p.z + step(rng)};
    }
    return out;
}

// Candidate i's sphere and next sphere, as the selection's read batch lists them.
struct Candidates {
    std::vector<std::size_t> at, next;
};

Candidates candidates(std::size_t spheres, std::size_t n, std::mt19937& rng) {
    std::uniform_int_distribution<std::size_t> pick(0, spheres - 2);
    Candidates c;
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t k = pick(rng);
        c.at.push_back(k);
        c.next.push_back(i % 5 == 2 ? SIZE_MAX : k + 1);
    }
    return c;
}

// The bounds of n random candidates along `spheres`, joins of up to 2 mm.
BlockBounds bounds_along(const std::vector<Sphere>& spheres, std::size_t n, std::mt19937& rng) {
    const Candidates c = candidates(spheres.size(), n, rng);
    BlockBounds bounds;
    bounds.compute(spheres.data(), c.at.data(), c.next.data(), n, 2.0f);
    return bounds;
}

TEST(BlockBounds, ComputeEqualsBlockBoundBitForBit) {
    std::mt19937 rng(3);
    const std::vector<Sphere> spheres = fiber_spheres(200, rng);
    for (const float join : {0.0f, 0.3f, 4.0f, 1e7f, -1.0f})
        for (std::size_t n = 0; n <= 41; n += (n < 9 ? 1 : 8)) {
            const Candidates c = candidates(spheres.size(), n, rng);
            for (const bool avx2 : {true, false}) {
                SCOPED_TRACE(testing::Message() << "join " << join << " n " << n << " avx2 " << avx2);
                const test::ScopedSimdLoops loops(avx2);
                BlockBounds bounds;
                bounds.compute(spheres.data(), c.at.data(), c.next.data(), n, join);
                ASSERT_EQ(bounds.size(), n);
                for (std::size_t i = 0; i < n; ++i) {
                    const BlockBound one =
                        detail::block_bound(spheres[c.at[i]], c.next[i] != SIZE_MAX ? &spheres[c.next[i]] : nullptr, join);
                    const BlockBound many = bounds[i];
                    EXPECT_EQ(std::memcmp(&one, &many, sizeof(BlockBound)), 0) << "candidate " << i;
                }
            }
        }
}

std::vector<Region> regions_near(const std::vector<Sphere>& spheres, std::mt19937& rng) {
    std::uniform_real_distribution<float> radius(0.1f, 6.0f);
    std::vector<Region> out;
    for (std::size_t k = 0; k < spheres.size(); k += 13) {
        const Vec3f c = spheres[k].center;
        out.push_back(Region::sphere({c.x + 5, c.y - 2, c.z + 1}, radius(rng)));
        out.push_back(Region::sphere(c, 0.0f));
    }
    out.push_back(Region::box_between({0, -40, -10}, {30, 0, 10}));
    return out;
}

TEST(BlockBounds, MayMeetEqualsBoundMayMeet) {
    std::mt19937 rng(4);
    const std::vector<Sphere> spheres = fiber_spheres(200, rng);
    const BlockBounds bounds = bounds_along(spheres, 39, rng);
    // And regions on each capsule's axis just past either end: missed only
    // because the nearest point of the segment is clamped to its ends.
    std::vector<Region> regions = regions_near(spheres, rng);
    for (std::size_t i = 0; i < bounds.size(); ++i) {
        const BlockBound b = bounds[i];
        const Vec3f u{b.b.x - b.a.x, b.b.y - b.a.y, b.b.z - b.a.z};
        const float len = std::sqrt(u.x * u.x + u.y * u.y + u.z * u.z);
        if (!(len > 0)) continue;
        const float past = b.radius * 1.2f + 1.0f, r = 0.5f;
        for (const float sign : {1.0f, -1.0f}) {
            const Vec3f end = sign > 0 ? b.b : b.a;
            regions.push_back(Region::sphere(
                {end.x + sign * u.x / len * (past + r), end.y + sign * u.y / len * (past + r), end.z + sign * u.z / len * (past + r)}, r));
        }
    }
    std::size_t met = 0, missed = 0;
    for (const Region& r : regions)
        for (const bool avx2 : {true, false}) {
            const test::ScopedSimdLoops loops(avx2);
            std::vector<std::uint8_t> meets(bounds.size(), 7);
            bounds.may_meet(r, meets.data());
            for (std::size_t i = 0; i < bounds.size(); ++i) {
                const bool one = detail::bound_may_meet(r, bounds[i]);
                EXPECT_EQ(meets[i], one ? 1 : 0) << "candidate " << i << " avx2 " << avx2;
                (one ? met : missed) += 1;
            }
        }
    EXPECT_GT(met, 0u);  // the regions both meet and miss bounds
    EXPECT_GT(missed, 0u);
}

// The test the selection relies on: a capsule that holds a point of the
// region is never said to miss it.
TEST(BlockBounds, AMetRegionIsNeverMissed) {
    std::mt19937 rng(5);
    const BlockBounds bounds = bounds_along(fiber_spheres(120, rng), 64, rng);
    std::uniform_real_distribution<float> unit(-1, 1), along(0, 1);
    std::size_t checked = 0;
    for (std::size_t i = 0; i < bounds.size(); ++i) {
        const BlockBound b = bounds[i];
        for (int s = 0; s < 20; ++s) {
            // A point of the capsule: on the segment, moved by less than the radius.
            const float t = along(rng);
            Vec3f d{unit(rng), unit(rng), unit(rng)};
            const float len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z), scale = b.radius * 0.999f * along(rng) / len;
            const Vec3f p{b.a.x + t * (b.b.x - b.a.x) + d.x * scale, b.a.y + t * (b.b.y - b.a.y) + d.y * scale,
                          b.a.z + t * (b.b.z - b.a.z) + d.z * scale};
            for (const Region& r : {Region::sphere({p.x + 0.5f, p.y, p.z}, 0.5f), Region::sphere(p, 0.0f)}) {
                std::vector<std::uint8_t> meets(bounds.size());
                bounds.may_meet(r, meets.data());
                EXPECT_EQ(meets[i], 1) << "candidate " << i;
                ++checked;
            }
        }
    }
    EXPECT_GT(checked, 0u);
}

}  // namespace
}  // namespace fiblet
