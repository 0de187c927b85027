#include "select/block_bounds.hpp"

#include <algorithm>
#include <cmath>

#include "core/float_lanes.hpp"
#include "core/grow.hpp"
#include "core/points_avx2.hpp"
#include "fiblet/image_mask.hpp"

namespace fiblet::detail {

void spheres_in_frustum(const Frustum& f, const Sphere* spheres, std::size_t n, std::uint8_t* out) {
    std::size_t k = 0;
    for (; k + 4 <= n; k += 4) {
        const Sphere* s = spheres + k;
        const Floats x = {s[0].center.x, s[1].center.x, s[2].center.x, s[3].center.x},
                     y = {s[0].center.y, s[1].center.y, s[2].center.y, s[3].center.y},
                     z = {s[0].center.z, s[1].center.z, s[2].center.z, s[3].center.z},
                     below = -Floats{s[0].radius, s[1].radius, s[2].radius, s[3].radius};
        Ints apart{};
        for (const Plane& p : f.planes) apart |= p.n.x * x + p.n.y * y + p.n.z * z + p.d < below;
        for (int l = 0; l < 4; ++l) out[k + std::size_t(l)] = apart[l] == 0;
    }
    for (; k < n; ++k) out[k] = sphere_intersects_frustum(f, spheres[k].center, spheres[k].radius);
}

BlockBound block_bound(const Sphere& s, const Sphere* next, float join) {
    BlockBound bound{s.center, s.center, s.radius};
    if (!next || join < 0) return bound;
    const Vec3f b = next->center;
    const double dx = double(b.x) - s.center.x, dy = double(b.y) - s.center.y, dz = double(b.z) - s.center.z;
    const double reach = double(s.radius) + double(join), d2 = dx * dx + dy * dy + dz * dz;
    if (d2 >= reach * reach) return bound;  // not a path the index describes: keep the sphere
    const double r = 0.5 * std::sqrt(reach * reach - d2) * (1 + 1e-5) + 1e-5 * reach;
    if (r < double(s.radius)) bound = {s.center, b, float(r)};
    return bound;
}

// The slack dwarfs float rounding of the points and of Region::contains.
bool bound_may_meet(const Region& r, const BlockBound& c) {
    const double R = double(c.radius);
    const double slack = 1e-3 + 1e-5 * (std::abs(double(c.a.x)) + std::abs(double(c.a.y)) + std::abs(double(c.a.z)) + R);
    const double reach = R + slack;
    if (r.shape == Region::Shape::sphere) {
        // Distance from the centre to the segment a-b.
        const double ux = double(c.b.x) - c.a.x, uy = double(c.b.y) - c.a.y, uz = double(c.b.z) - c.a.z;
        const double wx = double(r.center.x) - c.a.x, wy = double(r.center.y) - c.a.y, wz = double(r.center.z) - c.a.z;
        const double uu = ux * ux + uy * uy + uz * uz;
        const double t = uu > 0 ? std::clamp((wx * ux + wy * uy + wz * uz) / uu, 0.0, 1.0) : 0.0;
        const double ex = wx - t * ux, ey = wy - t * uy, ez = wz - t * uz, far = reach + r.radius;
        return ex * ex + ey * ey + ez * ez <= far * far;
    }
    // Boxes and masks: the capsule's bounding box.
    const auto e = float(reach);
    const Aabb b{{std::min(c.a.x, c.b.x) - e, std::min(c.a.y, c.b.y) - e, std::min(c.a.z, c.b.z) - e},
                 {std::max(c.a.x, c.b.x) + e, std::max(c.a.y, c.b.y) + e, std::max(c.a.z, c.b.z) + e}};
    if (r.shape == Region::Shape::box)
        return !(b.max.x < r.box.min.x || b.min.x > r.box.max.x || b.max.y < r.box.min.y || b.min.y > r.box.max.y ||
                 b.max.z < r.box.min.z || b.min.z > r.box.max.z);
    return r.mask->classify(b) != ImageMask::Overlap::outside;
}

void BlockBounds::set(std::size_t i, const BlockBound& c) {
    ax_[i] = c.a.x, ay_[i] = c.a.y, az_[i] = c.a.z, bx_[i] = c.b.x, by_[i] = c.b.y, bz_[i] = c.b.z, radius_[i] = c.radius;
}

namespace {
#ifdef FIBLET_POINTS_AVX2
#define FIBLET_AVX2 __attribute__((target("avx2")))

// Four spheres (rows) as columns x, y, z, radius.
FIBLET_AVX2 inline void sphere_columns(const Sphere* s0, const Sphere* s1, const Sphere* s2, const Sphere* s3,
                                       __m128& x, __m128& y, __m128& z, __m128& r) {
    x = _mm_loadu_ps(&s0->center.x), y = _mm_loadu_ps(&s1->center.x), z = _mm_loadu_ps(&s2->center.x);
    r = _mm_loadu_ps(&s3->center.x);
    _MM_TRANSPOSE4_PS(x, y, z, r);
}

FIBLET_AVX2 inline __m256d widen(__m128 v) { return _mm256_cvtps_pd(v); }

// block_bound for bounds [0, n / 4 * 4), four at a time: the same double
// operations in the same order (vsqrtpd rounds as std::sqrt; a lane without
// a next sphere, or whose comparisons fail, including on NaN, keeps its
// sphere, as the scalar branches do). Returns the bounds done.
FIBLET_AVX2 std::size_t bounds_avx2(const Sphere* spheres, const std::size_t* at, const std::size_t* next,
                                    std::size_t n, float join, float* ax, float* ay, float* az, float* bx, float* by,
                                    float* bz, float* radius) {
    const __m256d join_d = _mm256_set1_pd(double(join)), half = _mm256_set1_pd(0.5), grow = _mm256_set1_pd(1 + 1e-5),
                  pad = _mm256_set1_pd(1e-5);
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        const Sphere* s[4];
        const Sphere* t[4];
        int has_next = 0;  // bit l: lane l has a next sphere
        for (int l = 0; l < 4; ++l) {
            s[l] = &spheres[at[i + l]];
            has_next |= int(next[i + l] != SIZE_MAX) << l;
            t[l] = next[i + l] != SIZE_MAX ? &spheres[next[i + l]] : s[l];
        }
        __m128 sx, sy, sz, sr, tx, ty, tz, tr;
        sphere_columns(s[0], s[1], s[2], s[3], sx, sy, sz, sr);
        sphere_columns(t[0], t[1], t[2], t[3], tx, ty, tz, tr);
        const __m256d dx = _mm256_sub_pd(widen(tx), widen(sx)), dy = _mm256_sub_pd(widen(ty), widen(sy)),
                      dz = _mm256_sub_pd(widen(tz), widen(sz));  // tr unused: only the next centre counts
        const __m256d reach = _mm256_add_pd(widen(sr), join_d), d2 = norm2(dx, dy, dz);
        const __m256d reach2 = _mm256_mul_pd(reach, reach);
        const __m256d r = _mm256_add_pd(_mm256_mul_pd(_mm256_mul_pd(half, _mm256_sqrt_pd(_mm256_sub_pd(reach2, d2))), grow),
                                        _mm256_mul_pd(pad, reach));
        // Narrowed where there is a next sphere, !(d2 >= reach^2) and r < radius.
        const __m256d narrowed = _mm256_andnot_pd(_mm256_cmp_pd(d2, reach2, _CMP_GE_OQ),
                                                  _mm256_cmp_pd(r, widen(sr), _CMP_LT_OQ));
        const __m128i lane_bit = _mm_setr_epi32(1, 2, 4, 8);
        const __m128 narrow = _mm_castsi128_ps(_mm_cmpeq_epi32(
            _mm_and_si128(_mm_set1_epi32(_mm256_movemask_pd(narrowed) & has_next), lane_bit), lane_bit));
        _mm_storeu_ps(ax + i, sx), _mm_storeu_ps(ay + i, sy), _mm_storeu_ps(az + i, sz);
        _mm_storeu_ps(bx + i, _mm_blendv_ps(sx, tx, narrow)), _mm_storeu_ps(by + i, _mm_blendv_ps(sy, ty, narrow));
        _mm_storeu_ps(bz + i, _mm_blendv_ps(sz, tz, narrow));
        _mm_storeu_ps(radius + i, _mm_blendv_ps(sr, _mm256_cvtpd_ps(r), narrow));
    }
    return i;
}

FIBLET_AVX2 inline __m256d abs_pd(__m256d v) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), v); }

// bound_may_meet of sphere region r for bounds [0, n / 4 * 4), four at a
// time: the same double operations in the same order (vdivpd rounds as /;
// the clamp by comparisons and blends, which let a NaN through as
// std::clamp does). Returns the bounds done.
FIBLET_AVX2 std::size_t sphere_meets_avx2(const Region& region, std::size_t n, const float* ax, const float* ay,
                                          const float* az, const float* bx, const float* by, const float* bz,
                                          const float* radius, std::uint8_t* out) {
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0), small = _mm256_set1_pd(1e-3),
                  per = _mm256_set1_pd(1e-5), cx = _mm256_set1_pd(double(region.center.x)),
                  cy = _mm256_set1_pd(double(region.center.y)), cz = _mm256_set1_pd(double(region.center.z)),
                  region_radius = _mm256_set1_pd(double(region.radius));
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        const __m256d x = widen(_mm_loadu_ps(ax + i)), y = widen(_mm_loadu_ps(ay + i)), z = widen(_mm_loadu_ps(az + i));
        const __m256d R = widen(_mm_loadu_ps(radius + i));
        const __m256d slack =
            _mm256_add_pd(small, _mm256_mul_pd(per, _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(abs_pd(x), abs_pd(y)), abs_pd(z)), R)));
        const __m256d reach = _mm256_add_pd(R, slack);
        const __m256d ux = _mm256_sub_pd(widen(_mm_loadu_ps(bx + i)), x), uy = _mm256_sub_pd(widen(_mm_loadu_ps(by + i)), y),
                      uz = _mm256_sub_pd(widen(_mm_loadu_ps(bz + i)), z);
        const __m256d wx = _mm256_sub_pd(cx, x), wy = _mm256_sub_pd(cy, y), wz = _mm256_sub_pd(cz, z);
        const __m256d uu = norm2(ux, uy, uz);
        const __m256d dot =
            _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(wx, ux), _mm256_mul_pd(wy, uy)), _mm256_mul_pd(wz, uz));
        __m256d t = _mm256_div_pd(dot, uu);
        t = _mm256_blendv_pd(t, zero, _mm256_cmp_pd(t, zero, _CMP_LT_OQ));
        t = _mm256_blendv_pd(t, one, _mm256_cmp_pd(one, t, _CMP_LT_OQ));
        t = _mm256_and_pd(_mm256_cmp_pd(uu, zero, _CMP_GT_OQ), t);  // uu > 0 ? t : +0
        const __m256d ex = _mm256_sub_pd(wx, _mm256_mul_pd(t, ux)), ey = _mm256_sub_pd(wy, _mm256_mul_pd(t, uy)),
                      ez = _mm256_sub_pd(wz, _mm256_mul_pd(t, uz));
        const __m256d far = _mm256_add_pd(reach, region_radius);
        const int meets = _mm256_movemask_pd(_mm256_cmp_pd(norm2(ex, ey, ez), _mm256_mul_pd(far, far), _CMP_LE_OQ));
        for (int l = 0; l < 4; ++l) out[i + l] = std::uint8_t(meets >> l & 1);
    }
    return i;
}
#undef FIBLET_AVX2
#endif
}  // namespace

void BlockBounds::may_meet(const Region& r, std::uint8_t* out) const {
    std::size_t i = 0;
#ifdef FIBLET_POINTS_AVX2
    if (use_avx2_loops() && r.shape == Region::Shape::sphere)
        i = sphere_meets_avx2(r, n_, ax_.data(), ay_.data(), az_.data(), bx_.data(), by_.data(), bz_.data(),
                              radius_.data(), out);
#endif
    for (; i < n_; ++i) out[i] = bound_may_meet(r, (*this)[i]);
}

void BlockBounds::compute(const Sphere* spheres, const std::size_t* at, const std::size_t* next, std::size_t n,
                          float join) {
    n_ = n;
    for (auto* c : {&ax_, &ay_, &az_, &bx_, &by_, &bz_, &radius_}) grow(*c, n);
    std::size_t i = 0;
#ifdef FIBLET_POINTS_AVX2
    if (use_avx2_loops() && join >= 0)
        i = bounds_avx2(spheres, at, next, n, join, ax_.data(), ay_.data(), az_.data(), bx_.data(), by_.data(),
                        bz_.data(), radius_.data());
#endif
    for (; i < n; ++i) set(i, block_bound(spheres[at[i]], next[i] != SIZE_MAX ? &spheres[next[i]] : nullptr, join));
}

}  // namespace fiblet::detail
