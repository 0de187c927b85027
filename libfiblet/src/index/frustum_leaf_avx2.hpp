// Internal: the blocks of a leaf that meets a frustum partly, their eight
// packed boxes unpacked and tested in one AVX2 vector: FrustumTest's float
// operations lane by lane (the far corners only: a leaf hands no planes
// down, and frustum walks ask for no blocks wholly inside), so the same
// blocks as the four-float lanes of box_tests.hpp, without their per-half
// 64-bit unpacking, which SSE2 does a few operations at a time.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/points_avx2.hpp"
#include "index/box_tests.hpp"

namespace fiblet::detail {

#ifdef FIBLET_POINTS_AVX2
// The low 32 bits of the eight 64-bit words of a and b, in their order.
__attribute__((target("avx2"))) inline __m256i low_words8(__m256i a, __m256i b) {
    // a0 a1 b0 b1 | a2 a3 b2 b3, then a0 .. a3 b0 .. b3
    const __m256 halves = _mm256_shuffle_ps(_mm256_castsi256_ps(a), _mm256_castsi256_ps(b), _MM_SHUFFLE(2, 0, 2, 0));
    return _mm256_permute4x64_epi64(_mm256_castps_si256(halves), _MM_SHUFFLE(3, 1, 2, 0));
}

// Bit i set where box i of the n (1 <= n <= 8) packed boxes at `cells`
// (layout L, cells of `cell` mm from origin) is not outside the frustum
// grown by t.margin, by the planes in `active`.
template <CellLayout L>
__attribute__((target("avx2"))) unsigned frustum_leaf_avx2(const FrustumTest& t, const std::uint64_t* cells,
                                                           std::size_t n, Vec3f origin, float cell, Narrowing active) {
    std::uint64_t padded[kBoxLanes];  // box 0 again past n, as BoxLanes::of_cells
    if (n < kBoxLanes) {
        for (std::size_t i = 0; i < kBoxLanes; ++i) padded[i] = cells[i < n ? i : 0];
        cells = padded;
    }
    const __m256i w0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(cells));
    const __m256i w1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(cells + 4));
    const __m256i all_ones = _mm256_set1_epi64x(-1);
    const __m256 unbounded = _mm256_castsi256_ps(low_words8(_mm256_cmpeq_epi64(w0, all_ones), _mm256_cmpeq_epi64(w1, all_ones)));
    const float m = unbounded_box().max.x, unit = cell / float(L.subdivision);
    const float o[3] = {origin.x, origin.y, origin.z};
    const __m256i lo_mask = _mm256_set1_epi32((1 << L.lo_bits) - 1), extent_mask = _mm256_set1_epi32((1 << L.extent_bits) - 1);
    __m256 lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
        const __m128i shift = _mm_cvtsi32_si128(int(L.axis_bits()) * a);
        const __m256i fields = low_words8(_mm256_srl_epi64(w0, shift), _mm256_srl_epi64(w1, shift));
        const __m256i first = _mm256_and_si256(fields, lo_mask);
        const __m256i last = _mm256_add_epi32(first, _mm256_and_si256(_mm256_srli_epi32(fields, L.lo_bits), extent_mask));
        // o + float(i) * unit, as cells_bounds; unbounded: the float range
        const __m256 side_lo = _mm256_add_ps(_mm256_set1_ps(o[a]), _mm256_mul_ps(_mm256_cvtepi32_ps(first), _mm256_set1_ps(unit)));
        const __m256 side_hi = _mm256_add_ps(_mm256_set1_ps(o[a]), _mm256_mul_ps(_mm256_cvtepi32_ps(last), _mm256_set1_ps(unit)));
        lo[a] = _mm256_blendv_ps(side_lo, _mm256_set1_ps(-m), unbounded);
        hi[a] = _mm256_blendv_ps(side_hi, _mm256_set1_ps(m), unbounded);
    }
    __m256 outside = _mm256_setzero_ps();
    for (std::size_t k = 0; k < t.f.planes.size(); ++k) {
        if (!(active >> k & 1)) continue;
        const Plane& p = t.f.planes[k];
        // The corner farthest along n: n.x * x + n.y * y + n.z * z + d, in that order.
        const __m256 x = p.n.x >= 0 ? hi[0] : lo[0], y = p.n.y >= 0 ? hi[1] : lo[1], z = p.n.z >= 0 ? hi[2] : lo[2];
        const __m256 far = _mm256_add_ps(
            _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(p.n.x), x), _mm256_mul_ps(_mm256_set1_ps(p.n.y), y)),
                          _mm256_mul_ps(_mm256_set1_ps(p.n.z), z)),
            _mm256_set1_ps(p.d));
        outside = _mm256_or_ps(outside, _mm256_cmp_ps(far, _mm256_set1_ps(-t.margin), _CMP_LT_OQ));
    }
    return ~unsigned(_mm256_movemask_ps(outside)) & ((1u << n) - 1);
}
#endif

}  // namespace fiblet::detail
