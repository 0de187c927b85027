// The kernels' vector type on AVX2 (8 float lanes, FMA). Included by
// decode_avx2.cpp inside its namespace and `#pragma GCC target` region; the
// interface is the one of simd_portable.inl.

struct V {
    static constexpr int W = 8;
    using F = __m256;
    using M = __m256;

    static F set1(float x) { return _mm256_set1_ps(x); }
    static F load(const float* p) { return _mm256_load_ps(p); }
    static void store(float* p, F a) { _mm256_store_ps(p, a); }
    static void storeu(float* p, F a) { _mm256_storeu_ps(p, a); }
    static void store_n(float* p, F a, int n) {
        if (n == W) return _mm256_storeu_ps(p, a);
        const __m256i mask = _mm256_cmpgt_epi32(_mm256_set1_epi32(n), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
        _mm256_maskstore_ps(p, mask, a);
    }
    static F add(F a, F b) { return _mm256_add_ps(a, b); }
    static F sub(F a, F b) { return _mm256_sub_ps(a, b); }
    static F mul(F a, F b) { return _mm256_mul_ps(a, b); }
    static F fmadd(F a, F b, F c) { return _mm256_fmadd_ps(a, b, c); }
    static F div(F a, F b) { return _mm256_div_ps(a, b); }
    static F sqrt(F a) { return _mm256_sqrt_ps(a); }
    static M less(F a, F b) { return _mm256_cmp_ps(a, b, _CMP_LT_OQ); }
    static F select(M m, F if_true, F if_false) { return _mm256_blendv_ps(if_false, if_true, m); }
    static F with_lane0(F a, float x) { return _mm256_blend_ps(a, _mm256_set1_ps(x), 1); }
    static F broadcast_last(F a) { return _mm256_permutevar8x32_ps(a, _mm256_set1_epi32(W - 1)); }

    // Row loads and an 8 x 8 transpose (components 0..7) beat 9 gathers
    // (about 2x on Zen 4); component 8 comes from scalar loads.
    // `code_at(j)`: where lane j's code is.
    template <class Code = Code8, class CodeAt>
    static void lookup(const float* rows, CodeAt code_at, F (&out)[9]) {
        const float* row[8];
        F r[8];
        for (int j = 0; j < 8; ++j) row[j] = rows + 16 * Code::at(code_at(j)), r[j] = _mm256_load_ps(row[j]);
        transpose(r);
        for (int c = 0; c < 8; ++c) out[c] = r[c];
        out[8] = _mm256_setr_ps(row[0][8], row[1][8], row[2][8], row[3][8], row[4][8], row[5][8], row[6][8], row[7][8]);
    }

    static void transpose(F (&r)[W]) {
        F t[8], s[8];
        for (int i = 0; i < 4; ++i) {
            t[2 * i] = _mm256_unpacklo_ps(r[2 * i], r[2 * i + 1]);
            t[2 * i + 1] = _mm256_unpackhi_ps(r[2 * i], r[2 * i + 1]);
        }
        for (int i = 0; i < 2; ++i) {
            s[4 * i] = _mm256_shuffle_ps(t[4 * i], t[4 * i + 2], 0x44);
            s[4 * i + 1] = _mm256_shuffle_ps(t[4 * i], t[4 * i + 2], 0xee);
            s[4 * i + 2] = _mm256_shuffle_ps(t[4 * i + 1], t[4 * i + 3], 0x44);
            s[4 * i + 3] = _mm256_shuffle_ps(t[4 * i + 1], t[4 * i + 3], 0xee);
        }
        for (int i = 0; i < 4; ++i) {
            r[i] = _mm256_permute2f128_ps(s[i], s[i + 4], 0x20);
            r[i + 4] = _mm256_permute2f128_ps(s[i], s[i + 4], 0x31);
        }
    }
    template <int D>
    static F shift_up(F cur, F prev) {
        const __m256i rot = _mm256_setr_epi32((0 - D) & 7, (1 - D) & 7, (2 - D) & 7, (3 - D) & 7, (4 - D) & 7, (5 - D) & 7,
                                        (6 - D) & 7, (7 - D) & 7);
        return _mm256_blend_ps(_mm256_permutevar8x32_ps(cur, rot), _mm256_permutevar8x32_ps(prev, rot), (1 << D) - 1);
    }

    // Output float 8q + j is component (8q + j) % 3 of point (8q + j) / 3.
    static constexpr int blend_bits(int q, int c) {
        int bits = 0;
        for (int j = 0; j < 8; ++j) bits |= ((8 * q + j) % 3 == c) << j;
        return bits;
    }
    template <int Q>
    static F interleave(F x, F y, F z) {
        const __m256i idx = _mm256_setr_epi32((8 * Q) / 3, (8 * Q + 1) / 3, (8 * Q + 2) / 3, (8 * Q + 3) / 3, (8 * Q + 4) / 3,
                                        (8 * Q + 5) / 3, (8 * Q + 6) / 3, (8 * Q + 7) / 3);
        const F xy = _mm256_blend_ps(_mm256_permutevar8x32_ps(x, idx), _mm256_permutevar8x32_ps(y, idx),
                                     blend_bits(Q, 1));
        return _mm256_blend_ps(xy, _mm256_permutevar8x32_ps(z, idx), blend_bits(Q, 2));
    }
    static void store_xyz(float* p, F x, F y, F z, int n) {
        const int floats = 3 * n;
        if (floats > 0) store_n(p, interleave<0>(x, y, z), std::min(floats, 8));
        if (floats > 8) store_n(p + 8, interleave<1>(x, y, z), std::min(floats - 8, 8));
        if (floats > 16) store_n(p + 16, interleave<2>(x, y, z), floats - 16);
    }
};
