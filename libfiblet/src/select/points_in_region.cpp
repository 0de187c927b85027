#include "select/points_in_region.hpp"

#include "fiblet/image_mask.hpp"

#include "core/points_avx2.hpp"

namespace fiblet::detail {

namespace {

// Region::contains's float operations, the shape chosen once.
struct SpherePoints {
    float cx, cy, cz, r2;
    bool operator()(const float* q) const {
        const float dx = q[0] - cx, dy = q[1] - cy, dz = q[2] - cz;
        return dx * dx + dy * dy + dz * dz <= r2;
    }
};
struct BoxPoints {
    Aabb b;
    bool operator()(const float* q) const {
        return (q[0] >= b.min.x) & (q[0] <= b.max.x) & (q[1] >= b.min.y) & (q[1] <= b.max.y) & (q[2] >= b.min.z) &
               (q[2] <= b.max.z);
    }
};

#ifdef FIBLET_POINTS_AVX2
// The same tests on points k .. k + 7 as float columns: the same operations
// in the same order (-ffp-contract=off), so the same answer point by point.
__attribute__((target("avx2"))) inline __m256 inside8(const SpherePoints& s, __m256 x, __m256 y, __m256 z) {
    const __m256 dx = _mm256_sub_ps(x, _mm256_set1_ps(s.cx)), dy = _mm256_sub_ps(y, _mm256_set1_ps(s.cy)),
                 dz = _mm256_sub_ps(z, _mm256_set1_ps(s.cz));
    const __m256 d2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
    return _mm256_cmp_ps(d2, _mm256_set1_ps(s.r2), _CMP_LE_OQ);
}
__attribute__((target("avx2"))) inline __m256 within8(__m256 v, float lo, float hi) {
    return _mm256_and_ps(_mm256_cmp_ps(v, _mm256_set1_ps(lo), _CMP_GE_OQ), _mm256_cmp_ps(v, _mm256_set1_ps(hi), _CMP_LE_OQ));
}
__attribute__((target("avx2"))) inline __m256 inside8(const BoxPoints& t, __m256 x, __m256 y, __m256 z) {
    return _mm256_and_ps(_mm256_and_ps(within8(x, t.b.min.x, t.b.max.x), within8(y, t.b.min.y, t.b.max.y)),
                         within8(z, t.b.min.z, t.b.max.z));
}

// Points [0, n / 8 * 8): true at the first eight holding one inside; `done`
// the points tested.
template <class Test>
__attribute__((target("avx2"))) bool any_inside_avx2(const Test& test, const float* p, std::uint32_t n, std::uint32_t& done) {
    const auto* points = reinterpret_cast<const Vec3f*>(p);
    std::uint32_t k = 0;
    for (; k + 8 <= n; k += 8) {
        __m256 x, y, z;
        xyz8(points + k, x, y, z);
        if (_mm256_movemask_ps(inside8(test, x, y, z)) != 0) return true;
    }
    done = k;
    return false;
}
#endif

template <class Test>
bool any_inside(const Test& test, const float* p, std::uint32_t n) {
    std::uint32_t k = 0;
#ifdef FIBLET_POINTS_AVX2
    if (use_avx2_loops() && any_inside_avx2(test, p, n, k)) return true;
#endif
    for (; k < n; ++k)
        if (test(p + 3 * k)) return true;
    return false;
}

}  // namespace

bool any_point_in(const Region& r, const float* p, std::uint32_t n) {
    switch (r.shape) {
        case Region::Shape::mask: return r.mask->contains_any(p, n);
        case Region::Shape::sphere:
            return any_inside(SpherePoints{r.center.x, r.center.y, r.center.z, r.radius * r.radius}, p, n);
        case Region::Shape::box: return any_inside(BoxPoints{r.box}, p, n);
    }
    return false;
}

bool any_point_in(const std::vector<Region>& regions, const float* p, std::uint32_t n) {
    for (const Region& r : regions)
        if (any_point_in(r, p, n)) return true;
    return false;
}

}  // namespace fiblet::detail
