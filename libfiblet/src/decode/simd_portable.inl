// The kernels' vector type in plain C++: W floats in an array, every
// operation a loop (compilers vectorize what they can). Included by
// decode_portable.cpp inside its namespace; see decode_kernels.hpp.
// Like the other simd_*.inl files it defines `struct V`: W lanes, float
// vectors F, lane masks M, and the few operations the kernels use.

struct V {
    static constexpr int W = 8;
    struct F {
        alignas(32) float v[W];
    };

    struct M {
        bool v[W];
    };

    static F set1(float x) {
        F r;
        for (int j = 0; j < W; ++j) r.v[j] = x;
        return r;
    }
    static F load(const float* p) {
        F r;
        std::memcpy(r.v, p, sizeof r.v);
        return r;
    }
    static void store(float* p, F a) { std::memcpy(p, a.v, sizeof a.v); }
    // First n lanes (0 <= n <= W) to p, unaligned.
    static void storeu(float* p, F a) { std::memcpy(p, a.v, sizeof a.v); }
    static void store_n(float* p, F a, int n) { std::memcpy(p, a.v, sizeof(float) * std::size_t(n)); }
    static F add(F a, F b) {
        for (int j = 0; j < W; ++j) a.v[j] = a.v[j] + b.v[j];
        return a;
    }
    static F sub(F a, F b) {
        for (int j = 0; j < W; ++j) a.v[j] = a.v[j] - b.v[j];
        return a;
    }
    static F mul(F a, F b) {
        for (int j = 0; j < W; ++j) a.v[j] = a.v[j] * b.v[j];
        return a;
    }
    // a * b + c, fused where the instruction set has it (warp path only).
    static F fmadd(F a, F b, F c) {
        for (int j = 0; j < W; ++j) c.v[j] = a.v[j] * b.v[j] + c.v[j];
        return c;
    }
    static F div(F a, F b) {
        for (int j = 0; j < W; ++j) a.v[j] = a.v[j] / b.v[j];
        return a;
    }
    static F sqrt(F a) {
        for (int j = 0; j < W; ++j) a.v[j] = std::sqrt(a.v[j]);
        return a;
    }
    static M less(F a, F b) {
        M m;
        for (int j = 0; j < W; ++j) m.v[j] = a.v[j] < b.v[j];
        return m;
    }
    static F select(M m, F if_true, F if_false) {
        for (int j = 0; j < W; ++j) if_false.v[j] = m.v[j] ? if_true.v[j] : if_false.v[j];
        return if_false;
    }
    static F with_lane0(F a, float x) {
        a.v[0] = x;
        return a;
    }
    static F broadcast_last(F a) { return set1(a.v[W - 1]); }

    // The local frames of W codes (lane j's at code_at(j)) from the table
    // of padded rows (DecodeContext::frame_rows), component-major.
    template <class Code = Code8, class CodeAt>
    static void lookup(const float* rows, CodeAt code_at, F (&out)[9]) {
        for (int j = 0; j < W; ++j) {
            const float* row = rows + 16 * Code::at(code_at(j));
            for (int c = 0; c < 9; ++c) out[c].v[j] = row[c];
        }
    }

    // Rows r[0..W) become the columns.
    static void transpose(F (&r)[W]) {
        for (int i = 0; i < W; ++i)
            for (int j = i + 1; j < W; ++j) std::swap(r[i].v[j], r[j].v[i]);
    }
    // Lanes shifted up by D across a pair of vectors: lane j of the result is
    // lane j - D of `cur`, or lane W - D + j of `prev` for j < D (0 < D < W).
    template <int D>
    static F shift_up(F cur, F prev) {
        F r;
        for (int j = 0; j < W; ++j) r.v[j] = j >= D ? cur.v[j - D] : prev.v[W - D + j];
        return r;
    }
    // The first n points (n <= W) of lanes x, y, z to p as x0 y0 z0 x1 ...
    static void store_xyz(float* p, F x, F y, F z, int n) {
        for (int j = 0; j < n; ++j) p[3 * j] = x.v[j], p[3 * j + 1] = y.v[j], p[3 * j + 2] = z.v[j];
    }
};
