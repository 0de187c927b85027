// Internal: the blocks of a leaf that meets a region partly, their eight
// packed boxes unpacked and tested in one AVX2 vector, where box_tests.hpp
// takes two halves of four-float lanes and SSE2 unpacks the 64-bit cells a
// few operations at a time. Each test repeats the float operations of its
// box_tests.hpp twin lane by lane, so the same blocks come out (a frustum:
// the far corners only, since no frustum walk asks for blocks wholly inside
// and a leaf hands no planes down). Run where use_avx2_loops() says.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/points_avx2.hpp"
#include "index/box_tests.hpp"

namespace fiblet::detail {

#ifdef FIBLET_POINTS_AVX2
#define FIBLET_AVX2 __attribute__((target("avx2"))) inline

// Eight boxes: per axis, their low and high sides.
struct BoxLanes8 {
    __m256 lo[3], hi[3];
};

// Which of a leaf's boxes meet the region (bit i: box i) and which lie in it.
struct LeafVerdicts {
    unsigned near = 0, inside = 0;
};

// The low 32 bits of the eight 64-bit words of a and b, in their order.
FIBLET_AVX2 __m256i low_words8(__m256i a, __m256i b) {
    // a0 a1 b0 b1 | a2 a3 b2 b3, then a0 .. a3 b0 .. b3
    const __m256 halves = _mm256_shuffle_ps(_mm256_castsi256_ps(a), _mm256_castsi256_ps(b), _MM_SHUFFLE(2, 0, 2, 0));
    return _mm256_permute4x64_epi64(_mm256_castps_si256(halves), _MM_SHUFFLE(3, 1, 2, 0));
}

// BoxLanes::of_cells in one vector: the n (1 <= n <= 8) packed boxes at
// `cells` (layout L, cells of `cell` mm from origin), box 0 again past n.
template <CellLayout L>
FIBLET_AVX2 BoxLanes8 unpack_cells8(const std::uint64_t* cells, std::size_t n, Vec3f origin, float cell) {
    std::uint64_t padded[kBoxLanes];
    cells = eight_cells(cells, n, padded);
    const __m256i w0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(cells));
    const __m256i w1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(cells + 4));
    const __m256i all_ones = _mm256_set1_epi64x(-1);
    const __m256 unbounded = _mm256_castsi256_ps(low_words8(_mm256_cmpeq_epi64(w0, all_ones), _mm256_cmpeq_epi64(w1, all_ones)));
    const float m = unbounded_box().max.x, unit = cell / float(L.subdivision);
    const float o[3] = {origin.x, origin.y, origin.z};
    const __m256i lo_mask = _mm256_set1_epi32((1 << L.lo_bits) - 1), extent_mask = _mm256_set1_epi32((1 << L.extent_bits) - 1);
    BoxLanes8 b;
    for (int a = 0; a < 3; ++a) {
        const __m128i shift = _mm_cvtsi32_si128(int(L.axis_bits()) * a);
        const __m256i fields = low_words8(_mm256_srl_epi64(w0, shift), _mm256_srl_epi64(w1, shift));
        const __m256i first = _mm256_and_si256(fields, lo_mask);
        const __m256i last = _mm256_add_epi32(first, _mm256_and_si256(_mm256_srli_epi32(fields, L.lo_bits), extent_mask));
        // o + float(i) * unit, as cells_bounds; unbounded: the float range
        const __m256 side_lo = _mm256_add_ps(_mm256_set1_ps(o[a]), _mm256_mul_ps(_mm256_cvtepi32_ps(first), _mm256_set1_ps(unit)));
        const __m256 side_hi = _mm256_add_ps(_mm256_set1_ps(o[a]), _mm256_mul_ps(_mm256_cvtepi32_ps(last), _mm256_set1_ps(unit)));
        b.lo[a] = _mm256_blendv_ps(side_lo, _mm256_set1_ps(-m), unbounded);
        b.hi[a] = _mm256_blendv_ps(side_hi, _mm256_set1_ps(m), unbounded);
    }
    return b;
}

// The first n lanes of an outside mask and of a within mask as verdicts.
FIBLET_AVX2 LeafVerdicts verdicts8(__m256 outside, __m256 within, std::size_t n) {
    const unsigned lanes = (1u << n) - 1, apart = unsigned(_mm256_movemask_ps(outside));
    return {~apart & lanes, ~apart & unsigned(_mm256_movemask_ps(within)) & lanes};
}

// FrustumTest::classify's outside verdicts (its planes in `active`).
FIBLET_AVX2 LeafVerdicts leaf_verdicts8(const FrustumTest& t, const BoxLanes8& b, std::size_t n, Narrowing active) {
    __m256 outside = _mm256_setzero_ps();
    for (std::size_t k = 0; k < t.f.planes.size(); ++k) {
        if (!(active >> k & 1)) continue;
        const Plane& p = t.f.planes[k];
        // The corner farthest along n: n.x * x + n.y * y + n.z * z + d, in that order.
        const __m256 x = p.n.x >= 0 ? b.hi[0] : b.lo[0], y = p.n.y >= 0 ? b.hi[1] : b.lo[1], z = p.n.z >= 0 ? b.hi[2] : b.lo[2];
        const __m256 far = _mm256_add_ps(
            _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(p.n.x), x), _mm256_mul_ps(_mm256_set1_ps(p.n.y), y)),
                          _mm256_mul_ps(_mm256_set1_ps(p.n.z), z)),
            _mm256_set1_ps(p.d));
        outside = _mm256_or_ps(outside, _mm256_cmp_ps(far, _mm256_set1_ps(-t.margin), _CMP_LT_OQ));
    }
    return verdicts8(outside, _mm256_setzero_ps(), n);
}

// SphereTest::classify.
FIBLET_AVX2 LeafVerdicts leaf_verdicts8(const SphereTest& t, const BoxLanes8& b, std::size_t n, Narrowing) {
    const float c[3] = {t.c.x, t.c.y, t.c.z};
    const __m256 zero = _mm256_setzero_ps();
    __m256 near2 = zero, far2 = zero;
    for (int a = 0; a < 3; ++a) {
        const __m256 centre = _mm256_set1_ps(c[a]);
        // below < 0 ? 0 : below (vmaxps returns its second operand on a tie and for NaN, as the ternary)
        const __m256 below = _mm256_sub_ps(b.lo[a], centre), above = _mm256_sub_ps(centre, b.hi[a]);
        const __m256 d = _mm256_add_ps(_mm256_blendv_ps(below, zero, _mm256_cmp_ps(below, zero, _CMP_LT_OQ)),
                                       _mm256_blendv_ps(above, zero, _mm256_cmp_ps(above, zero, _CMP_LT_OQ)));
        const __m256 to_lo = _mm256_sub_ps(centre, b.lo[a]), to_hi = _mm256_sub_ps(b.hi[a], centre);
        const __m256 f = _mm256_blendv_ps(to_lo, to_hi, _mm256_cmp_ps(to_lo, to_hi, _CMP_LT_OQ));
        near2 = _mm256_add_ps(near2, _mm256_mul_ps(d, d));
        far2 = _mm256_add_ps(far2, _mm256_mul_ps(f, f));
    }
    return verdicts8(_mm256_cmp_ps(near2, _mm256_set1_ps(t.r2_out), _CMP_GT_OQ),
                     _mm256_cmp_ps(far2, _mm256_set1_ps(t.r2_in), _CMP_LE_OQ), n);
}

// BoxTest::classify.
FIBLET_AVX2 LeafVerdicts leaf_verdicts8(const BoxTest& t, const BoxLanes8& b, std::size_t n, Narrowing) {
    const float rlo[3] = {t.r.min.x, t.r.min.y, t.r.min.z}, rhi[3] = {t.r.max.x, t.r.max.y, t.r.max.z};
    __m256 outside = _mm256_setzero_ps(), within = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
    for (int a = 0; a < 3; ++a) {
        const __m256 lo = _mm256_set1_ps(rlo[a]), hi = _mm256_set1_ps(rhi[a]);
        outside = _mm256_or_ps(outside, _mm256_or_ps(_mm256_cmp_ps(b.hi[a], lo, _CMP_LT_OQ), _mm256_cmp_ps(b.lo[a], hi, _CMP_GT_OQ)));
        within = _mm256_and_ps(within, _mm256_and_ps(_mm256_cmp_ps(b.lo[a], lo, _CMP_GE_OQ), _mm256_cmp_ps(b.hi[a], hi, _CMP_LE_OQ)));
    }
    return verdicts8(outside, within, n);
}

// Tests with an AVX2 twin here.
template <class Test>
concept HasLeafVerdicts8 = requires(const Test& t, const BoxLanes8& b) { leaf_verdicts8(t, b, std::size_t{}, Narrowing{}); };

// The verdicts on a leaf's n packed boxes (unpack_cells8's arguments): the
// one entry from code built without AVX2 (vectors stay inside).
template <CellLayout L, class Test>
__attribute__((target("avx2"))) LeafVerdicts leaf_verdicts_avx2(const Test& t, const std::uint64_t* cells, std::size_t n,
                                                                Vec3f origin, float cell, Narrowing active) {
    return leaf_verdicts8(t, unpack_cells8<L>(cells, n, origin, cell), n, active);
}

#undef FIBLET_AVX2
#endif

}  // namespace fiblet::detail
