#include "encode/anchor_conditioning.hpp"

#include <algorithm>
#include <cmath>

#include "core/block_geometry.hpp"
#include "core/points_avx2.hpp"
#include "fiblet/fft_format.hpp"

namespace fiblet::detail {

namespace {

Vec3d float_anchor(const std::array<std::uint32_t, 3>& q) {
    return {unpack_unorm16(std::uint16_t(q[0])), unpack_unorm16(std::uint16_t(q[1])), unpack_unorm16(std::uint16_t(q[2]))};
}
Vec3d exact_anchor(const std::array<std::uint32_t, 3>& q) {
    return {exact_unorm16(q[0]), exact_unorm16(q[1]), exact_unorm16(q[2])};
}

// How much a unit of divergence counts against a unit of anchor error in
// the choice of roundings. The robust code search absorbs much of the
// divergence that remains, while the anchor error is paid in full: on the
// stress test of first segments within 1 degree of the helper
// (exact_stress_test.cpp) 0.1 gives a max error of 1.98 um (the same
// fibers turned away from C: 1.37 um; no conditioning: 12.5 um); 0.03
// gives 4.31 (too little conditioning), 0.3 2.24 and 1 2.51 (anchors moved
// a whole quantum for little gain).
constexpr double kDivergenceWeight = 0.1;

// How many quanta the second anchor may move to leave the fallback's cone.
constexpr int kFallbackQuanta = 4;

double unorm16_value(double n) { return std::clamp(n, 0.0, 1.0) * 65535.0; }

// The larger of the two anchors' distances to where they should be.
double anchor_error(const AnchorWords& w, Vec3d n0, Vec3d n1) {
    const Vec3d e0 = exact_anchor(w.a0) - n0, e1 = exact_anchor(w.a1) - n1;
    return std::sqrt(std::max(dot(e0, e0), dot(e1, e1)));
}

}  // namespace

DecoderStarts decoder_starts(const AnchorWords& w) {
    DecoderStarts s;
    s.words = w;
    s.a0 = to_float(float_anchor(w.a0)), s.a1 = to_float(float_anchor(w.a1));
    const Vec3f axis = anchor_axis(s.a0, s.a1);
    s.frame = frame_from_axis(axis);
    s.exact0 = exact_anchor(w.a0), s.exact1 = exact_anchor(w.a1);
    const Vec3d exact_axis = exact_block_axis(s.exact0, s.exact1);
    s.exact_frame = exact_frame_from_axis(exact_axis);
    s.fallback = frame_uses_fallback(axis) || exact_frame_uses_fallback(exact_axis);
    return s;
}

double start_divergence(const DecoderStarts& s, double reach) {
    double frame2 = 0;
    for (int i = 0; i < 3; ++i) {
        const Vec3d d = s.exact_frame.c[i] - to_double(s.frame.c[i]);
        frame2 += dot(d, d);
    }
    const Vec3d da = s.exact1 - to_double(s.a1);
    return std::sqrt(dot(da, da)) + std::sqrt(frame2) * reach;
}

namespace {

// The anchors' values rounded down (bit i of up_mask: up) or to the nearest.
AnchorWords rounded_words(Vec3d n0, Vec3d n1, unsigned up_mask, bool nearest) {
    const double v[6] = {unorm16_value(n0.x), unorm16_value(n0.y), unorm16_value(n0.z),
                         unorm16_value(n1.x), unorm16_value(n1.y), unorm16_value(n1.z)};
    AnchorWords w;
    for (int i = 0; i < 6; ++i) {
        const double r = nearest ? std::round(v[i]) : (up_mask >> i & 1) ? std::ceil(v[i]) : std::floor(v[i]);
        (i < 3 ? w.a0 : w.a1)[i % 3] = std::uint32_t(std::clamp(r, 0.0, 65535.0));
    }
    return w;
}

}  // namespace

AnchorWords nearest_words(Vec3d n0, Vec3d n1) { return rounded_words(n0, n1, 0, true); }

DecoderStarts condition_anchors(Vec3d n0, Vec3d n1, double reach, double threshold, const DecoderStarts& nearest) {
    DecoderStarts best = nearest;
    bool fallback = best.fallback;
    if (!(best.divergence > threshold) && !fallback) return best;
    double best_cost = fallback ? INFINITY : anchor_error(best.words, n0, n1) + kDivergenceWeight * best.divergence;
    auto offer = [&](const AnchorWords& w) {
        // The divergence only adds to the anchor error: a rounding whose
        // anchors alone cost the best so far cannot win, and is not decoded.
        const double error = anchor_error(w, n0, n1);
        if (!(error < best_cost)) return;
        DecoderStarts s = decoder_starts(w);
        if (s.fallback) return;
        s.divergence = start_divergence(s, reach);
        const double cost = error + kDivergenceWeight * s.divergence;
        if (cost < best_cost) best_cost = cost, best = s, fallback = false;
    };
    for (unsigned mask = 0; mask < 64; ++mask) offer(rounded_words(n0, n1, mask, false));
    // Anchors on the grid round one way only: the second one moved by a
    // quantum on each axis turns the first axis away from C (a 0.1 mm step
    // turns by 1.7 degrees a quantum of a 200 mm box, the fallback's cone is 0.06).
    for (int q = 1; fallback && q <= kFallbackQuanta; ++q)
        for (int i = 0; i < 27; ++i) {
            if (i == 13) continue;  // no move: the nearest rounding, refused above
            AnchorWords w = nearest.words;
            for (int a = 0, code = i; a < 3; ++a, code /= 3)
                w.a1[a] = std::uint32_t(std::clamp<std::int64_t>(std::int64_t(w.a1[a]) + (code % 3 - 1) * q, 0, 65535));
            offer(w);
        }
    return best;
}

#ifdef FIBLET_POINTS_AVX2
namespace {

#define FIBLET_AVX2 __attribute__((target("avx2"))) inline

// The lanes' arithmetic in float (SSE: four blocks) and in double (AVX2:
// four blocks), so that the vector operations below are written once, in
// the scalar ones' order (vec_math.hpp, exact_model.hpp).
FIBLET_AVX2 __m128 add(__m128 a, __m128 b) { return _mm_add_ps(a, b); }
FIBLET_AVX2 __m256d add(__m256d a, __m256d b) { return _mm256_add_pd(a, b); }
FIBLET_AVX2 __m128 sub(__m128 a, __m128 b) { return _mm_sub_ps(a, b); }
FIBLET_AVX2 __m256d sub(__m256d a, __m256d b) { return _mm256_sub_pd(a, b); }
FIBLET_AVX2 __m128 mul(__m128 a, __m128 b) { return _mm_mul_ps(a, b); }
FIBLET_AVX2 __m256d mul(__m256d a, __m256d b) { return _mm256_mul_pd(a, b); }
FIBLET_AVX2 __m128 blend(__m128 mask, __m128 yes, __m128 no) { return _mm_blendv_ps(no, yes, mask); }
FIBLET_AVX2 __m256d blend(__m256d mask, __m256d yes, __m256d no) { return _mm256_blendv_pd(no, yes, mask); }
FIBLET_AVX2 __m128 splat(__m128, float v) { return _mm_set1_ps(v); }
FIBLET_AVX2 __m256d splat(__m256d, float v) { return _mm256_set1_pd(double(v)); }
// 1 / sqrt(v), as the scalar 1 / std::sqrt(v): both correctly rounded.
FIBLET_AVX2 __m128 inverse_root(__m128 v) { return _mm_div_ps(_mm_set1_ps(1.0f), _mm_sqrt_ps(v)); }
FIBLET_AVX2 __m256d inverse_root(__m256d v) { return _mm256_div_pd(_mm256_set1_pd(1.0), _mm256_sqrt_pd(v)); }
// needs_fallback's test of |c1|^2 (1e-6f in float, 1e-6 in double), and n2 > 0.
FIBLET_AVX2 __m128 too_short(__m128 n2) { return _mm_cmplt_ps(n2, _mm_set1_ps(1e-6f)); }
FIBLET_AVX2 __m256d too_short(__m256d n2) { return _mm256_cmp_pd(n2, _mm256_set1_pd(1e-6), _CMP_LT_OQ); }
FIBLET_AVX2 __m128 positive(__m128 v) { return _mm_cmpgt_ps(v, _mm_setzero_ps()); }
FIBLET_AVX2 __m256d positive(__m256d v) { return _mm256_cmp_pd(v, _mm256_setzero_pd(), _CMP_GT_OQ); }

// Four 3-vectors, one per lane, in float and in double; the operations
// below are written once for both (V: V3f or V3d).
struct V3f {
    __m128 x, y, z;
};
struct V3d {
    __m256d x, y, z;
};
template <class V>
FIBLET_AVX2 auto dot4(V a, V b) {
    return add(add(mul(a.x, b.x), mul(a.y, b.y)), mul(a.z, b.z));
}
template <class V>
FIBLET_AVX2 V cross4(V a, V b) {
    return {sub(mul(a.y, b.z), mul(a.z, b.y)), sub(mul(a.z, b.x), mul(a.x, b.z)), sub(mul(a.x, b.y), mul(a.y, b.x))};
}
template <class V>
FIBLET_AVX2 V minus(V a, V b) {
    return {sub(a.x, b.x), sub(a.y, b.y), sub(a.z, b.z)};
}
template <class V, class Mask>
FIBLET_AVX2 V select4(Mask mask, V yes, V no) {
    return {blend(mask, yes.x, no.x), blend(mask, yes.y, no.y), blend(mask, yes.z, no.z)};
}
template <class V>
FIBLET_AVX2 V unit4(V a) {  // (1 / |a|) a
    const auto s = inverse_root(dot4(a, a));
    return {mul(s, a.x), mul(s, a.y), mul(s, a.z)};
}
template <class V>
FIBLET_AVX2 V splat3(V like, float x, float y, float z) {
    return {splat(like.x, x), splat(like.x, y), splat(like.x, z)};
}
FIBLET_AVX2 V3d widen(V3f a) { return {_mm256_cvtps_pd(a.x), _mm256_cvtps_pd(a.y), _mm256_cvtps_pd(a.z)}; }
// |e - f|^2 of exact and float vectors, in double.
FIBLET_AVX2 __m256d distance2(V3d e, V3f f) {
    const V3d d = minus(e, widen(f));
    return dot4(d, d);
}

// anchor_axis (float) and exact_block_axis (double) of four first segments d.
template <class V>
FIBLET_AVX2 V axis4(V d) {
    return select4(positive(dot4(d, d)), unit4(d), splat3(d, 1.0f, 0.0f, 0.0f));
}

// frame_from_axis (float) and exact_frame_from_axis (double) of four axes:
// both helpers' crosses, the fallback's taken where the first is too short
// (as the scalar branch), into frame columns c; `fallback`: where it was.
template <class V, class Mask>
FIBLET_AVX2 void frames4(V axis, V c[3], Mask& fallback) {
    const V c1 = cross4(axis, splat3(axis, kFrameHelper[0], kFrameHelper[1], kFrameHelper[2]));
    fallback = too_short(dot4(c1, c1));
    c[0] = axis;
    c[1] = unit4(select4(fallback, cross4(axis, splat3(axis, 0.0f, kFrameHelper[2], -kFrameHelper[1])), c1));
    c[2] = unit4(cross4(axis, c[1]));
}

__attribute__((target("avx2"))) void decoder_starts4_avx2(const AnchorWords w[4], const double reach[4],
                                                          DecoderStarts out[4]) {
    // The words as lanes: word[a][k] = anchor a's coordinate k of each block.
    alignas(16) std::int32_t q[2][3][4];
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) q[0][k][i] = std::int32_t(w[i].a0[k]), q[1][k][i] = std::int32_t(w[i].a1[k]);
    auto words = [&](int a, int k) { return _mm_load_si128(reinterpret_cast<const __m128i*>(q[a][k])); };
    // The anchors: unpack_unorm16 (float) and exact_unorm16 (double).
    V3f f[2];
    V3d e[2];
    for (int a = 0; a < 2; ++a) {
        __m128 v[3];
        __m256d d[3];
        for (int k = 0; k < 3; ++k) {
            const __m128i qk = words(a, k);
            v[k] = _mm_div_ps(_mm_cvtepi32_ps(qk), _mm_set1_ps(65535.0f));
            d[k] = _mm256_div_pd(_mm256_cvtepi32_pd(qk), _mm256_set1_pd(65535.0));  // exact_unorm16
        }
        f[a] = {v[0], v[1], v[2]}, e[a] = {d[0], d[1], d[2]};
    }
    // Float: anchor_axis, frame_from_axis.
    V3f frame[3];
    __m128 float_fallback;
    frames4(axis4(minus(f[1], f[0])), frame, float_fallback);
    // Double: exact_block_axis, exact_frame_from_axis.
    V3d exact[3];
    __m256d exact_fallback;
    frames4(axis4(minus(e[1], e[0])), exact, exact_fallback);
    // start_divergence: the frames' Frobenius distance (columns summed in
    // order) times the reach, plus the second anchors' distance.
    const __m256d frame2 = add(add(distance2(exact[0], frame[0]), distance2(exact[1], frame[1])), distance2(exact[2], frame[2]));
    const __m256d divergence = _mm256_add_pd(_mm256_sqrt_pd(distance2(e[1], f[1])),
                                             _mm256_mul_pd(_mm256_sqrt_pd(frame2), _mm256_loadu_pd(reach)));
    // Out, a block at a time.
    alignas(32) float fl[2][3][4], fr[3][3][4];
    alignas(32) double el[2][3][4], er[3][3][4], dv[4];
    for (int a = 0; a < 2; ++a) {
        _mm_store_ps(fl[a][0], f[a].x), _mm_store_ps(fl[a][1], f[a].y), _mm_store_ps(fl[a][2], f[a].z);
        _mm256_store_pd(el[a][0], e[a].x), _mm256_store_pd(el[a][1], e[a].y), _mm256_store_pd(el[a][2], e[a].z);
    }
    for (int c = 0; c < 3; ++c) {
        _mm_store_ps(fr[c][0], frame[c].x), _mm_store_ps(fr[c][1], frame[c].y), _mm_store_ps(fr[c][2], frame[c].z);
        _mm256_store_pd(er[c][0], exact[c].x), _mm256_store_pd(er[c][1], exact[c].y), _mm256_store_pd(er[c][2], exact[c].z);
    }
    _mm256_store_pd(dv, divergence);
    const int fallback = _mm_movemask_ps(float_fallback) | _mm256_movemask_pd(exact_fallback);
    for (int i = 0; i < 4; ++i) {
        DecoderStarts& s = out[i];
        s.words = w[i];
        s.a0 = {fl[0][0][i], fl[0][1][i], fl[0][2][i]}, s.a1 = {fl[1][0][i], fl[1][1][i], fl[1][2][i]};
        s.exact0 = {el[0][0][i], el[0][1][i], el[0][2][i]}, s.exact1 = {el[1][0][i], el[1][1][i], el[1][2][i]};
        for (int c = 0; c < 3; ++c) {
            s.frame.c[c] = {fr[c][0][i], fr[c][1][i], fr[c][2][i]};
            s.exact_frame.c[c] = {er[c][0][i], er[c][1][i], er[c][2][i]};
        }
        s.divergence = dv[i];
        s.fallback = (fallback >> i & 1) != 0;
    }
}

#undef FIBLET_AVX2
}  // namespace
#endif

void decoder_starts4(const AnchorWords w[4], const double reach[4], DecoderStarts out[4]) {
#ifdef FIBLET_POINTS_AVX2
    if (use_avx2_loops()) return decoder_starts4_avx2(w, reach, out);
#endif
    for (int i = 0; i < 4; ++i) {
        out[i] = decoder_starts(w[i]);
        out[i].divergence = start_divergence(out[i], reach[i]);
    }
}

}  // namespace fiblet::detail
