// Internal: hand-written AVX2 (and a few AVX-512) loops over arrays of
// Vec3f (x86-64, GCC and Clang), and the switches that send them to their
// narrower or scalar twins. Every loop using these repeats its scalar
// loop's double operations in the same order (the library builds with
// -ffp-contract=off), so all give the same bits; tests switch the AVX-512
// and AVX2 loops off to check that (per thread).
#pragma once

#include "fiblet/geometry.hpp"

#if defined(__GNUC__) && defined(__x86_64__)
#define FIBLET_POINTS_AVX2 1
#include <immintrin.h>
#endif

namespace fiblet::detail {

// On by default; tests switch it around one computation.
inline bool& avx2_loops_enabled() {
    thread_local bool enabled = true;
    return enabled;
}

// Whether the AVX2 loops run: the CPU has AVX2 and they are not switched off.
inline bool use_avx2_loops() {
#ifdef FIBLET_POINTS_AVX2
    static const bool cpu = __builtin_cpu_supports("avx2");
    return cpu && avx2_loops_enabled();
#else
    return false;
#endif
}

// On by default; tests switch it off to run the AVX2 loops where the
// AVX-512 ones would run.
inline bool& avx512_loops_enabled() {
    thread_local bool enabled = true;
    return enabled;
}

// Whether the AVX-512 loops (eight doubles a vector) run: the CPU has
// AVX-512 F, DQ, BW and VL, and they and the AVX2 loops are switched on.
inline bool use_avx512_loops() {
#ifdef FIBLET_POINTS_AVX2
    static const bool cpu = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                            __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl");
    return cpu && avx512_loops_enabled() && use_avx2_loops();
#else
    return false;
#endif
}

#ifdef FIBLET_POINTS_AVX2
// Lanes idx of v, the low four.
__attribute__((target("avx2"))) inline __m128 low_lanes(__m256 v, __m256i idx) {
    return _mm256_castps256_ps128(_mm256_permutevar8x32_ps(v, idx));
}

// Points p .. p + 3 as columns of doubles (exact: float to double), from
// two overlapping loads of their 12 floats instead of gathers.
__attribute__((target("avx2"))) inline void xyz4(const Vec3f* p, __m256d& x, __m256d& y, __m256d& z) {
    static_assert(sizeof(Vec3f) == 3 * sizeof(float), "points are 3 packed floats");
    const float* f = &p->x;
    const __m256 lo = _mm256_loadu_ps(f), hi = _mm256_loadu_ps(f + 4);  // floats 0..7 and 4..11
    x = _mm256_cvtps_pd(_mm_blend_ps(low_lanes(lo, _mm256_setr_epi32(0, 3, 6, 0, 0, 0, 0, 0)),
                                     low_lanes(hi, _mm256_setr_epi32(0, 0, 0, 5, 0, 0, 0, 0)), 0b1000));
    y = _mm256_cvtps_pd(_mm_blend_ps(low_lanes(lo, _mm256_setr_epi32(1, 4, 7, 0, 0, 0, 0, 0)),
                                     low_lanes(hi, _mm256_setr_epi32(0, 0, 0, 6, 0, 0, 0, 0)), 0b1000));
    z = _mm256_cvtps_pd(_mm_blend_ps(low_lanes(lo, _mm256_setr_epi32(2, 5, 0, 0, 0, 0, 0, 0)),
                                     low_lanes(hi, _mm256_setr_epi32(0, 0, 4, 7, 0, 0, 0, 0)), 0b1100));
}

// Points p .. p + 7 as float columns, from three loads of their 24 floats:
// each register's lanes blended from the three (x0 x3 x6 x1 x4 x7 x2 x5,
// and likewise for y and z), then put in order.
__attribute__((target("avx2"))) inline void xyz8(const Vec3f* p, __m256& x, __m256& y, __m256& z) {
    static_assert(sizeof(Vec3f) == 3 * sizeof(float), "points are 3 packed floats");
    const float* f = &p->x;
    const __m256 m0 = _mm256_loadu_ps(f), m1 = _mm256_loadu_ps(f + 8), m2 = _mm256_loadu_ps(f + 16);
    x = _mm256_permutevar8x32_ps(_mm256_blend_ps(_mm256_blend_ps(m0, m1, 0b10010010), m2, 0b00100100),
                                 _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5));
    y = _mm256_permutevar8x32_ps(_mm256_blend_ps(_mm256_blend_ps(m0, m1, 0b00100100), m2, 0b01001001),
                                 _mm256_setr_epi32(1, 4, 7, 2, 5, 0, 3, 6));
    z = _mm256_permutevar8x32_ps(_mm256_blend_ps(_mm256_blend_ps(m0, m1, 0b01001001), m2, 0b10010010),
                                 _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7));
}

// Lanes 4 half .. 4 half + 3 of b - a in double, each side converted first
// (exact): the double difference of the two floats.
__attribute__((target("avx2"))) inline __m256d double_diff(__m256 b, __m256 a, int half) {
    const __m128 b4 = half ? _mm256_extractf128_ps(b, 1) : _mm256_castps256_ps128(b);
    const __m128 a4 = half ? _mm256_extractf128_ps(a, 1) : _mm256_castps256_ps128(a);
    return _mm256_sub_pd(_mm256_cvtps_pd(b4), _mm256_cvtps_pd(a4));
}

// The segments from points p .. p + 7 to the next ones (p[1] - p[0], ...)
// in double, four a half: from the float columns of the points and of their
// successors (a third of the lane-crossing shuffles of converting each
// point to double first). Reads points p .. p + 8.
__attribute__((target("avx2"))) inline void deltas8(const Vec3f* p, __m256d dx[2], __m256d dy[2], __m256d dz[2]) {
    __m256 x, y, z, nx, ny, nz;
    xyz8(p, x, y, z);
    xyz8(p + 1, nx, ny, nz);
    for (int h = 0; h < 2; ++h)
        dx[h] = double_diff(nx, x, h), dy[h] = double_diff(ny, y, h), dz[h] = double_diff(nz, z, h);
}

// The running bounds of points p .. p + n eight at a time into lo / hi,
// which start at +inf / -inf: three registers of 24 floats, whose lanes
// hold the same coordinate at every step (x y z x y z x y, z x y ...), keep
// minima and maxima (vminps / vmaxps return their second operand for a NaN,
// so a NaN coordinate is left out, as `p < lo ? p : lo` leaves it); returns
// the points done, the rest for the caller's scalar loop.
// (Six named registers: as arrays indexed in the loop, GCC kept them on the
// stack, a store and a reload a step.)
__attribute__((target("avx2"))) inline std::size_t bounds_avx2(const Vec3f* p, std::size_t n, float* lo, float* hi) {
    if (n < 8) return 0;
    const float* f = &p->x;
    __m256 mn0 = _mm256_set1_ps(lo[0]), mn1 = mn0, mn2 = mn0, mx0 = _mm256_set1_ps(hi[0]), mx1 = mx0, mx2 = mx0;
    std::size_t k = 0;
    for (; k + 8 <= n; k += 8) {
        const __m256 v0 = _mm256_loadu_ps(f + 3 * k), v1 = _mm256_loadu_ps(f + 3 * k + 8),
                     v2 = _mm256_loadu_ps(f + 3 * k + 16);
        mn0 = _mm256_min_ps(v0, mn0), mx0 = _mm256_max_ps(v0, mx0);
        mn1 = _mm256_min_ps(v1, mn1), mx1 = _mm256_max_ps(v1, mx1);
        mn2 = _mm256_min_ps(v2, mn2), mx2 = _mm256_max_ps(v2, mx2);
    }
    alignas(32) float lanes_lo[3][8], lanes_hi[3][8];
    _mm256_store_ps(lanes_lo[0], mn0), _mm256_store_ps(lanes_lo[1], mn1), _mm256_store_ps(lanes_lo[2], mn2);
    _mm256_store_ps(lanes_hi[0], mx0), _mm256_store_ps(lanes_hi[1], mx1), _mm256_store_ps(lanes_hi[2], mx2);
    // The 24 lanes in order are coordinates x y z x y z ...: eight points.
    const float *a = &lanes_lo[0][0], *b = &lanes_hi[0][0];
    float l[3] = {lo[0], lo[1], lo[2]}, h[3] = {hi[0], hi[1], hi[2]};
    for (int j = 0; j < 24; j += 3)
        for (int c = 0; c < 3; ++c)
            l[c] = a[j + c] < l[c] ? a[j + c] : l[c], h[c] = b[j + c] > h[c] ? b[j + c] : h[c];
    for (int c = 0; c < 3; ++c) lo[c] = l[c], hi[c] = h[c];
    return k;
}

// (dx dx + dy dy) + dz dz.
__attribute__((target("avx2"))) inline __m256d norm2(__m256d dx, __m256d dy, __m256d dz) {
    return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)), _mm256_mul_pd(dz, dz));
}
#endif

}  // namespace fiblet::detail
