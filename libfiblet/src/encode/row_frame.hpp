// Internal: the decoder's frame operations (vec_math.hpp) on four-float
// vectors, for the encoder's lookahead search.
//
// A frame is held as its three rows r_i = (c0[i], c1[i], c2[i], 0). Then
//   compose:          r'_i = (F[i][0] * L.r0 + F[i][1] * L.r1) + F[i][2] * L.r2
//   apply_transposed: (r0 * v.x + r1 * v.y) + r2 * v.z
// are, lane by lane, the very products and sums of vec_math.hpp's compose
// and apply_transposed in the same order (no fused multiply-add:
// -ffp-contract=off), so the results are bit-identical; three vector
// products and two sums replace nine scalar products and six sums.
// SSE2 where the compiler targets it (every x86-64), plain floats otherwise.
#pragma once

#include "core/vec_math.hpp"

#ifdef __SSE2__
#include <emmintrin.h>
#endif

namespace fiblet::detail {

#ifdef __SSE2__
using F4 = __m128;
inline F4 f4_set1(float a) { return _mm_set1_ps(a); }
inline F4 f4_of(Vec3f a) { return _mm_setr_ps(a.x, a.y, a.z, 0.0f); }
inline F4 f4_add(F4 a, F4 b) { return _mm_add_ps(a, b); }
inline F4 f4_sub(F4 a, F4 b) { return _mm_sub_ps(a, b); }
inline F4 f4_mul(F4 a, F4 b) { return _mm_mul_ps(a, b); }
inline F4 f4_load(const float* p) { return _mm_load_ps(p); }  // 16-byte aligned
inline void f4_store(float* p, F4 a) { _mm_store_ps(p, a); }
// std::max(a, b) = (a < b ? b : a) lane by lane: maxps returns its second
// operand for a NaN and for two zeros, as the ternary does.
inline F4 f4_max(F4 a, F4 b) { return _mm_max_ps(b, a); }
template <int i>
inline F4 f4_splat(F4 a) { return _mm_shuffle_ps(a, a, _MM_SHUFFLE(i, i, i, i)); }
template <int i>
inline float f4_lane(F4 a) { return _mm_cvtss_f32(_mm_shuffle_ps(a, a, _MM_SHUFFLE(i, i, i, i))); }
template <>
inline float f4_lane<0>(F4 a) { return _mm_cvtss_f32(a); }
// (a[0], b[0], c[0], 0)
inline F4 f4_firsts(F4 a, F4 b, F4 c) { return _mm_movelh_ps(_mm_unpacklo_ps(a, b), _mm_unpacklo_ps(c, _mm_setzero_ps())); }
// std::max(0.0f, a): maxss returns its second operand for a NaN and for two zeros, as the ternary does.
inline float max0(float a) { return _mm_cvtss_f32(_mm_max_ss(_mm_set_ss(a), _mm_setzero_ps())); }
#else
struct F4 {
    float v[4];
};
inline F4 f4_set1(float a) { return {{a, a, a, a}}; }
inline F4 f4_of(Vec3f a) { return {{a.x, a.y, a.z, 0.0f}}; }
inline F4 f4_add(F4 a, F4 b) { return {{a.v[0] + b.v[0], a.v[1] + b.v[1], a.v[2] + b.v[2], a.v[3] + b.v[3]}}; }
inline F4 f4_sub(F4 a, F4 b) { return {{a.v[0] - b.v[0], a.v[1] - b.v[1], a.v[2] - b.v[2], a.v[3] - b.v[3]}}; }
inline F4 f4_mul(F4 a, F4 b) { return {{a.v[0] * b.v[0], a.v[1] * b.v[1], a.v[2] * b.v[2], a.v[3] * b.v[3]}}; }
inline F4 f4_load(const float* p) { return {{p[0], p[1], p[2], p[3]}}; }
inline void f4_store(float* p, F4 a) {
    for (int i = 0; i < 4; ++i) p[i] = a.v[i];
}
inline F4 f4_max(F4 a, F4 b) {
    for (int i = 0; i < 4; ++i) a.v[i] = a.v[i] < b.v[i] ? b.v[i] : a.v[i];
    return a;
}
template <int i>
inline F4 f4_splat(F4 a) { return f4_set1(a.v[i]); }
template <int i>
inline float f4_lane(F4 a) { return a.v[i]; }
inline F4 f4_firsts(F4 a, F4 b, F4 c) { return {{a.v[0], b.v[0], c.v[0], 0.0f}}; }
inline float max0(float a) { return 0.0f < a ? a : 0.0f; }
#endif

inline Vec3f vec3_of(F4 a) { return {f4_lane<0>(a), f4_lane<1>(a), f4_lane<2>(a)}; }

struct RowFrame {
    F4 r[3];
};

inline RowFrame row_frame(const Frame& f) {
    return {{f4_of({f.c[0].x, f.c[1].x, f.c[2].x}), f4_of({f.c[0].y, f.c[1].y, f.c[2].y}),
             f4_of({f.c[0].z, f.c[1].z, f.c[2].z})}};
}
// Column 0: the frame's axis, the direction of the step it takes.
inline F4 axis(const RowFrame& f) { return f4_firsts(f.r[0], f.r[1], f.r[2]); }

// vec_math.hpp's compose(f, l), row by row.
inline RowFrame compose(const RowFrame& f, const RowFrame& l) {
    RowFrame o;
    for (int i = 0; i < 3; ++i)
        o.r[i] = f4_add(f4_add(f4_mul(f4_splat<0>(f.r[i]), l.r[0]), f4_mul(f4_splat<1>(f.r[i]), l.r[1])),
                        f4_mul(f4_splat<2>(f.r[i]), l.r[2]));
    return o;
}
// vec_math.hpp's apply_transposed(f, v).
inline F4 apply_transposed(const RowFrame& f, F4 v) {
    return f4_add(f4_add(f4_mul(f.r[0], f4_splat<0>(v)), f4_mul(f.r[1], f4_splat<1>(v))), f4_mul(f.r[2], f4_splat<2>(v)));
}
// vec_math.hpp's dot(v, v).
inline float dot_self(F4 v) {
    const float x = f4_lane<0>(v), y = f4_lane<1>(v), z = f4_lane<2>(v);
    return x * x + y * y + z * z;
}

}  // namespace fiblet::detail
