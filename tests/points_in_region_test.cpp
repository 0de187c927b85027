// detail::any_point_in (the selection's point tests, eight points at a time
// with AVX2) against Region::contains point by point, with and without the
// AVX2 loops: random blocks of points around spheres and boxes, points on
// their surfaces, and NaN points.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

#include "scoped_simd_loops.hpp"
#include "select/points_in_region.hpp"

namespace fiblet {
namespace {

using detail::any_point_in;

// A point near the region: inside, outside, exactly on a sphere's surface or
// a box's face, or NaN.
Vec3f near(const Region& r, std::mt19937& rng) {
    std::uniform_real_distribution<float> u(-1.5f, 1.5f);
    const unsigned kind = rng() % 8;
    if (kind == 0) return {std::numeric_limits<float>::quiet_NaN(), 0, 0};
    if (r.shape == Region::Shape::sphere) {
        if (kind == 1) return {r.center.x + r.radius, r.center.y, r.center.z};  // dx^2 == r^2 exactly
        return {r.center.x + r.radius * u(rng), r.center.y + r.radius * u(rng), r.center.z + r.radius * u(rng)};
    }
    const Vec3f mid{(r.box.min.x + r.box.max.x) / 2, (r.box.min.y + r.box.max.y) / 2, (r.box.min.z + r.box.max.z) / 2};
    const Vec3f half{(r.box.max.x - r.box.min.x) / 2, (r.box.max.y - r.box.min.y) / 2, (r.box.max.z - r.box.min.z) / 2};
    Vec3f p{mid.x + half.x * u(rng), mid.y + half.y * u(rng), mid.z + half.z * u(rng)};
    if (kind == 1) p.y = r.box.max.y;  // on a face
    return p;
}

bool brute_force(const std::vector<Region>& regions, const std::vector<Vec3f>& points) {
    for (const Vec3f& p : points)
        for (const Region& r : regions)
            if (r.contains(p)) return true;
    return false;
}

TEST(PointsInRegion, AnyPointInIsContainsOfEachPointAtEveryLevel) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> coordinate(-80, 80), size(0.5f, 20);
    std::size_t yes = 0, no = 0;
    for (int run = 0; run < 20000; ++run) {
        std::vector<Region> regions;
        for (unsigned k = 0, n = 1 + rng() % 2; k < n; ++k) {
            const Vec3f c{coordinate(rng), coordinate(rng), coordinate(rng)};
            const float s = size(rng);
            regions.push_back(rng() % 2 ? Region::sphere(c, s)
                                        : Region::box_between({c.x - s, c.y - 0.5f * s, c.z - 2 * s}, {c.x + s, c.y + s, c.z}));
        }
        // Up to 40 points: whole groups of eight and a rest, mostly outside.
        std::vector<Vec3f> points(rng() % 41);
        for (Vec3f& p : points)
            p = rng() % 16 == 0 ? near(regions[rng() % regions.size()], rng)
                                : Vec3f{coordinate(rng), coordinate(rng), coordinate(rng)};
        const bool expected = brute_force(regions, points);
        const auto* xyz = reinterpret_cast<const float*>(points.data());
        const auto n = std::uint32_t(points.size());
        for (const bool avx2 : {false, true}) {
            const test::ScopedSimdLoops loops(avx2);
            ASSERT_EQ(any_point_in(regions, xyz, n), expected) << "run " << run << ", AVX2 loops " << avx2;
            if (regions.size() == 1) {
                ASSERT_EQ(any_point_in(regions[0], xyz, n), expected) << "run " << run;
            }
        }
        (expected ? yes : no) += 1;
    }
    EXPECT_GT(yes, 3000u);
    EXPECT_GT(no, 3000u);
}

}  // namespace
}  // namespace fiblet
