// The kernels' vector type on AVX-512 (F, BW, DQ, VL: 16 float lanes).
// Included by decode_avx512.cpp inside its namespace and `#pragma GCC
// target` region; the interface is the one of simd_portable.inl.

struct V {
    static constexpr int W = 16;
    using F = __m512;
    using M = __mmask16;

    static F set1(float x) { return _mm512_set1_ps(x); }
    static F load(const float* p) { return _mm512_load_ps(p); }
    static void store(float* p, F a) { _mm512_store_ps(p, a); }
    static void storeu(float* p, F a) { _mm512_storeu_ps(p, a); }
    static void store_n(float* p, F a, int n) { _mm512_mask_storeu_ps(p, __mmask16((1u << n) - 1), a); }
    static F add(F a, F b) { return _mm512_add_ps(a, b); }
    static F sub(F a, F b) { return _mm512_sub_ps(a, b); }
    static F mul(F a, F b) { return _mm512_mul_ps(a, b); }
    static F fmadd(F a, F b, F c) { return _mm512_fmadd_ps(a, b, c); }
    static F div(F a, F b) { return _mm512_div_ps(a, b); }
    static F sqrt(F a) { return _mm512_sqrt_ps(a); }
    static M less(F a, F b) { return _mm512_cmp_ps_mask(a, b, _CMP_LT_OQ); }
    static F select(M m, F if_true, F if_false) { return _mm512_mask_blend_ps(m, if_false, if_true); }
    static F with_lane0(F a, float x) { return _mm512_mask_mov_ps(a, 1, _mm512_set1_ps(x)); }
    static F broadcast_last(F a) { return _mm512_permutexvar_ps(_mm512_set1_epi32(W - 1), a); }

    // 16 row loads and the part of a 16 x 16 transpose that yields
    // components 0..8 (57 shuffles): about 1.4x faster than 9 gathers on
    // Zen 4, where a 16-lane gather costs some 15 cycles. `code_at(j)`:
    // where lane j's code is.
    template <class Code = Code8, class CodeAt>
    static void lookup(const float* rows, CodeAt code_at, F (&out)[9]) {
        F r[16];
        for (int j = 0; j < 16; ++j) r[j] = _mm512_load_ps(rows + 16 * Code::at(code_at(j)));
        __m512d u[16];
        unpack_4x4(r, u);
        for (int s = 0; s < 4; ++s) {
            const __m512 lo_even = _mm512_shuffle_f32x4(_mm512_castpd_ps(u[s]), _mm512_castpd_ps(u[4 + s]), 0x88);
            const __m512 lo_odd = _mm512_shuffle_f32x4(_mm512_castpd_ps(u[s]), _mm512_castpd_ps(u[4 + s]), 0xdd);
            const __m512 hi_even = _mm512_shuffle_f32x4(_mm512_castpd_ps(u[8 + s]), _mm512_castpd_ps(u[12 + s]), 0x88);
            const __m512 hi_odd = _mm512_shuffle_f32x4(_mm512_castpd_ps(u[8 + s]), _mm512_castpd_ps(u[12 + s]), 0xdd);
            out[s] = _mm512_shuffle_f32x4(lo_even, hi_even, 0x88);
            out[s + 4] = _mm512_shuffle_f32x4(lo_odd, hi_odd, 0x88);
            if (s == 0) out[8] = _mm512_shuffle_f32x4(lo_even, hi_even, 0xdd);
        }
    }

    // First two stages of a 16 x 16 transpose: u[4g + s] holds rows
    // 4g..4g+3 of columns s, s + 4, s + 8, s + 12 (one per 128-bit lane).
    static void unpack_4x4(const F (&r)[16], __m512d (&u)[16]) {
        __m512 t[16];
        for (int i = 0; i < 8; ++i) {
            t[2 * i] = _mm512_unpacklo_ps(r[2 * i], r[2 * i + 1]);
            t[2 * i + 1] = _mm512_unpackhi_ps(r[2 * i], r[2 * i + 1]);
        }
        for (int g = 0; g < 4; ++g) {
            const __m512d a = _mm512_castps_pd(t[4 * g]), b = _mm512_castps_pd(t[4 * g + 1]);
            const __m512d c = _mm512_castps_pd(t[4 * g + 2]), d = _mm512_castps_pd(t[4 * g + 3]);
            u[4 * g] = _mm512_unpacklo_pd(a, c);
            u[4 * g + 1] = _mm512_unpackhi_pd(a, c);
            u[4 * g + 2] = _mm512_unpacklo_pd(b, d);
            u[4 * g + 3] = _mm512_unpackhi_pd(b, d);
        }
    }

    static void transpose(F (&r)[W]) {
        __m512d u[16];
        unpack_4x4(r, u);
        for (int s = 0; s < 4; ++s) {
            const __m512 lo_even = _mm512_shuffle_f32x4(_mm512_castpd_ps(u[s]), _mm512_castpd_ps(u[4 + s]), 0x88);
            const __m512 lo_odd = _mm512_shuffle_f32x4(_mm512_castpd_ps(u[s]), _mm512_castpd_ps(u[4 + s]), 0xdd);
            const __m512 hi_even = _mm512_shuffle_f32x4(_mm512_castpd_ps(u[8 + s]), _mm512_castpd_ps(u[12 + s]), 0x88);
            const __m512 hi_odd = _mm512_shuffle_f32x4(_mm512_castpd_ps(u[8 + s]), _mm512_castpd_ps(u[12 + s]), 0xdd);
            r[s] = _mm512_shuffle_f32x4(lo_even, hi_even, 0x88);
            r[s + 8] = _mm512_shuffle_f32x4(lo_even, hi_even, 0xdd);
            r[s + 4] = _mm512_shuffle_f32x4(lo_odd, hi_odd, 0x88);
            r[s + 12] = _mm512_shuffle_f32x4(lo_odd, hi_odd, 0xdd);
        }
    }
    template <int D>
    static F shift_up(F cur, F prev) {
        return _mm512_castsi512_ps(_mm512_alignr_epi32(_mm512_castps_si512(cur), _mm512_castps_si512(prev), W - D));
    }

    // Output float 16q + j is component (16q + j) % 3 of point (16q + j) / 3:
    // two two-source permutes, x with y, then the result with z.
    template <int Q>
    static F interleave(F x, F y, F z) {
        alignas(64) std::int32_t xy[16], xyz[16];
        for (int j = 0; j < 16; ++j) {
            const int o = 16 * Q + j, point = o / 3, c = o % 3;
            xy[j] = point + (c == 1 ? 16 : 0);
            xyz[j] = c == 2 ? 16 + point : j;
        }
        const F t = _mm512_permutex2var_ps(x, _mm512_load_si512(xy), y);
        return _mm512_permutex2var_ps(t, _mm512_load_si512(xyz), z);
    }
    static void store_xyz(float* p, F x, F y, F z, int n) {
        const int floats = 3 * n;
        if (floats > 0) store_n(p, interleave<0>(x, y, z), std::min(floats, 16));
        if (floats > 16) store_n(p + 16, interleave<1>(x, y, z), std::min(floats - 16, 16));
        if (floats > 32) store_n(p + 32, interleave<2>(x, y, z), floats - 32);
    }
};
