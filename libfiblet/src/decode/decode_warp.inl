// The "warp" decoder: the GPU scheme, one block at a time, SIMD registers
// playing the 32 lanes of a warp (32 / W registers per warp).
//
// Element e of a block is its first frame F0 for e = 0 and the local frame of
// direction byte e - 1 after; point e + 1 is reached with the frame
// F0 L0 ... L(e-1), the inclusive prefix product of elements 0..e. A block of
// 60 points has 59 elements: two warps, scanned side by side (Hillis-Steele:
// in pass d = 1, 2, 4, 8, 16 every lane multiplies the value d lanes below
// it into its own, identity below the warp's first lane), then the second
// warp is multiplied by the first warp's last frame. Positions: the steps
// step * frame.c0 (zero for element 0) summed by the same scan, anchor 1
// added last.
//
// The products and sums are reassociated (and fused multiply-adds are used),
// so points differ from the reference decoder by float rounding: bound and
// measurement in docs/decode.md. Included by decode_{portable,avx2,avx512}.cpp
// after the definition of V.

namespace warp {

constexpr int kWarpLanes = 32;
constexpr int kElements = 2 * kWarpLanes;  // covers blocks of up to 65 points
constexpr int kRegs = kElements / V::W;    // registers per component
constexpr int kRegsPerWarp = kWarpLanes / V::W;
constexpr bool kIdentity[9] = {true, false, false, false, true, false, false, false, true};

// value(reg) shifted up by D lanes within its warp; lanes below the warp's
// first lane take `fill`.
template <int D>
inline V::F shifted(const V::F* value, int reg, V::F fill) {
    constexpr int W = V::W;
    const int in_warp = reg % kRegsPerWarp;
    if constexpr (D < W) {
        return V::template shift_up<D>(value[reg], in_warp == 0 ? fill : value[reg - 1]);
    } else {
        constexpr int by = D / W;
        return in_warp >= by ? value[reg - by] : fill;
    }
}

// One Hillis-Steele pass of the frame product over registers [0, regs):
// m(lane) = m(lane - D) * m(lane). Highest register first, so every shifted
// value is read before it is overwritten.
template <int D>
inline void product_pass(V::F (&m)[9][kRegs], int regs, const V::F (&identity)[9]) {
    for (int reg = regs - 1; reg >= 0; --reg) {
        if (D >= V::W && reg % kRegsPerWarp < D / V::W) continue;  // multiplied by the identity
        V::F a[9];
        for (int c = 0; c < 9; ++c) a[c] = shifted<D>(m[c], reg, identity[c]);
        V::F b[9];
        for (int c = 0; c < 9; ++c) b[c] = m[c][reg];
        for (int j = 0; j < 3; ++j)
            for (int r = 0; r < 3; ++r)
                m[3 * j + r][reg] =
                    V::fmadd(a[6 + r], b[3 * j + 2], V::fmadd(a[3 + r], b[3 * j + 1], V::mul(a[r], b[3 * j])));
    }
}

template <int D>
inline void sum_pass(V::F (&s)[3][kRegs], int regs, V::F zero) {
    for (int reg = regs - 1; reg >= 0; --reg) {
        if (D >= V::W && reg % kRegsPerWarp < D / V::W) continue;
        for (int c = 0; c < 3; ++c) s[c][reg] = V::add(s[c][reg], shifted<D>(s[c], reg, zero));
    }
}

}  // namespace warp

// Over 80 lines with a reason: one SIMD kernel whose warp registers (the
// prefix products of 32 lanes) stay in registers through its passes.
// NOLINTNEXTLINE(readability-function-size): the reason above
inline std::size_t decode_warp(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count, float* xyz) {
    using F = V::F;
    constexpr int W = V::W;
    using namespace warp;
    const FftHeader& h = ctx.header;
    const std::size_t bb = h.block_bytes();
    const float* rows_table = ctx.frame_rows.data();
    const F step = V::set1(h.step), half = V::set1(0.5f), scaling = V::set1(h.scaling), zero = V::set1(0.0f);
    const F offset[3] = {V::set1(h.offset[0]), V::set1(h.offset[1]), V::set1(h.offset[2])};
    F identity[9];
    for (int c = 0; c < 9; ++c) identity[c] = V::set1(kIdentity[c] ? 1.0f : 0.0f);

    std::uint8_t element_code[kElements];
    float* out = xyz;
    for (std::size_t b = 0; b < count; ++b) {
        const BlockView block{blocks + b * bb};
        const int n = int(block.point_count());
        const BlockStart s = block_start(block);
        const Vec3f a0 = h.to_world(s.anchor0.x, s.anchor0.y, s.anchor0.z);
        out[0] = a0.x, out[1] = a0.y, out[2] = a0.z;
        if (n < 2) {
            out += 3;
            continue;
        }
        const int elements = n - 1;  // F0, then one per direction byte
        const int regs = elements <= kWarpLanes ? kRegsPerWarp : kRegs;

        // Every lane looks its local frame up (the bytes past the block's
        // count read as code 0 and are never written out).
        const std::uint8_t* codes = block.directions();
        element_code[0] = 0;
        for (int e = 1; e < regs * W; ++e) element_code[e] = e < elements ? codes[e - 1] : 0;
        F m[9][kRegs];
        for (int reg = 0; reg < regs; ++reg) {
            F local[9];
            V::lookup(rows_table, [&](int j) { return element_code + reg * W + j; }, local);
            for (int c = 0; c < 9; ++c) m[c][reg] = local[c];
        }
        const float f0[9] = {s.frame.c[0].x, s.frame.c[0].y, s.frame.c[0].z, s.frame.c[1].x, s.frame.c[1].y,
                             s.frame.c[1].z, s.frame.c[2].x, s.frame.c[2].y, s.frame.c[2].z};
        for (int c = 0; c < 9; ++c) m[c][0] = V::with_lane0(m[c][0], f0[c]);

        // Inclusive prefix product in log2(32) = 5 passes, both warps at once.
        product_pass<1>(m, regs, identity);
        product_pass<2>(m, regs, identity);
        product_pass<4>(m, regs, identity);
        product_pass<8>(m, regs, identity);
        product_pass<16>(m, regs, identity);
        if (regs > kRegsPerWarp) {
            // Chain the second warp to the first one's last frame.
            F last[9];
            for (int c = 0; c < 9; ++c) last[c] = V::broadcast_last(m[c][kRegsPerWarp - 1]);
            for (int reg = kRegsPerWarp; reg < regs; ++reg) {
                F q[9];
                for (int c = 0; c < 9; ++c) q[c] = m[c][reg];
                for (int j = 0; j < 3; ++j)
                    for (int r = 0; r < 3; ++r)
                        m[3 * j + r][reg] = V::fmadd(last[6 + r], q[3 * j + 2],
                                                     V::fmadd(last[3 + r], q[3 * j + 1], V::mul(last[r], q[3 * j])));
            }
        }

        // Steps, their inclusive prefix sum (5 passes), chained the same way.
        F sum[3][kRegs];
        for (int c = 0; c < 3; ++c)
            for (int reg = 0; reg < regs; ++reg) sum[c][reg] = V::mul(step, m[c][reg]);
        for (int c = 0; c < 3; ++c) sum[c][0] = V::with_lane0(sum[c][0], 0.0f);
        sum_pass<1>(sum, regs, zero);
        sum_pass<2>(sum, regs, zero);
        sum_pass<4>(sum, regs, zero);
        sum_pass<8>(sum, regs, zero);
        sum_pass<16>(sum, regs, zero);
        if (regs > kRegsPerWarp)
            for (int c = 0; c < 3; ++c) {
                const F last = V::broadcast_last(sum[c][kRegsPerWarp - 1]);
                for (int reg = kRegsPerWarp; reg < regs; ++reg) sum[c][reg] = V::add(sum[c][reg], last);
            }

        // Point e + 1 = anchor 1 + sum(e), in world coordinates.
        const float a1[3] = {s.anchor1.x, s.anchor1.y, s.anchor1.z};
        float* points = out + 3;
        for (int reg = 0; reg < regs; ++reg) {
            F w[3];
            for (int c = 0; c < 3; ++c)
                w[c] = V::sub(V::mul(V::sub(V::add(V::set1(a1[c]), sum[c][reg]), half), scaling), offset[c]);
            const int k = std::min(elements - reg * W, W);
            if (k <= 0) break;
            V::store_xyz(points + 3 * reg * W, w[0], w[1], w[2], k);
        }
        out += 3 * std::size_t(n);
    }
    return std::size_t(out - xyz) / 3;
}
