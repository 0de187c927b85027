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

// The segments from points p .. p + 3 to the next ones (p[1] - p[0], ...),
// in double: reads points p .. p + 4.
__attribute__((target("avx2"))) inline void deltas4(const Vec3f* p, __m256d& dx, __m256d& dy, __m256d& dz) {
    __m256d ax, ay, az, bx, by, bz;
    xyz4(p, ax, ay, az);
    xyz4(p + 1, bx, by, bz);
    dx = _mm256_sub_pd(bx, ax), dy = _mm256_sub_pd(by, ay), dz = _mm256_sub_pd(bz, az);
}

// (dx dx + dy dy) + dz dz.
__attribute__((target("avx2"))) inline __m256d norm2(__m256d dx, __m256d dy, __m256d dz) {
    return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)), _mm256_mul_pd(dz, dz));
}
#endif

}  // namespace fiblet::detail
