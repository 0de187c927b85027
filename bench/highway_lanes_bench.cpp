// The measurement behind the choice of plain intrinsics for the SIMD
// decoders (libfiblet/src/decode/simd_*.inl): the lanes decoder written
// with Highway's portable operations, for AVX2 and AVX-512, against the
// library's own lanes-avx2 / lanes-avx512 on the same blocks.
//
// Same algorithm and the same float operations (the output is checked bit
// for bit against the reference decoder); what differs is what Highway's
// portable API offers: the local frames come from 9 GatherIndex per step
// (Highway has no transpose; the intrinsics version loads W table rows and
// transposes them), and the output transposes are built from ConcatOdd /
// ConcatEven (log2 W rounds of W two-source permutes).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "highway_lanes_bench.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
//
#include <hwy/highway.h>

#include <algorithm>
#include <cstdint>
#include <utility>
#include <cstring>
#include <vector>

#include "fiblet/decode.hpp"

// Only the two targets measured are compiled (called directly, no dispatch).
#if HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3
HWY_BEFORE_NAMESPACE();
namespace fiblet_hwy {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
using fiblet::BlockView;
using fiblet::FftHeader;

// Rows r[0..W) become the columns: log2(W) rounds of unzipping pairs.
template <class D, class V>
HWY_INLINE void Transpose(D d, V* r, size_t w) {
    V n[16];
    for (size_t round = 1; round < w; round *= 2) {
        for (size_t i = 0; i < w / 2; ++i) {
            n[i] = hn::ConcatEven(d, r[2 * i + 1], r[2 * i]);
            n[i + w / 2] = hn::ConcatOdd(d, r[2 * i + 1], r[2 * i]);
        }
        for (size_t i = 0; i < w; ++i) r[i] = n[i];
    }
}

template <bool kRows>
size_t DecodeLanesT(const fiblet::DecodeContext& ctx, const float* HWY_RESTRICT soa, const uint8_t* blocks,
                    size_t count, float* xyz) {
    const hn::ScalableTag<float> d;
    const hn::RebindToSigned<decltype(d)> di;
    using V = hn::Vec<decltype(d)>;
    constexpr size_t kMaxW = 16;
    const size_t W = hn::Lanes(d);
    const FftHeader& h = ctx.header;
    const size_t bb = h.block_bytes();
    const V step = hn::Set(d, h.step), half = hn::Set(d, 0.5f), scaling = hn::Set(d, h.scaling);
    const V offset[3] = {hn::Set(d, h.offset[0]), hn::Set(d, h.offset[1]), hn::Set(d, h.offset[2])};
    const V zero = hn::Zero(d), one = hn::Set(d, 1.0f);
    HWY_ALIGN float words[6][kMaxW];
    HWY_ALIGN int32_t code[kMaxW];
    HWY_ALIGN float rows[3 * kMaxW][kMaxW];
    float* dst[kMaxW];
    int floats[kMaxW];
    std::vector<uint8_t> padded;
    float* out = xyz;

    struct Vec3 {
        V x, y, z;
    };
    auto dot = [](const Vec3& a, const Vec3& b) { return hn::Add(hn::Add(hn::Mul(a.x, b.x), hn::Mul(a.y, b.y)), hn::Mul(a.z, b.z)); };
    auto cross = [](const Vec3& a, const Vec3& b) {
        return Vec3{hn::Sub(hn::Mul(a.y, b.z), hn::Mul(a.z, b.y)), hn::Sub(hn::Mul(a.z, b.x), hn::Mul(a.x, b.z)),
                    hn::Sub(hn::Mul(a.x, b.y), hn::Mul(a.y, b.x))};
    };
    auto scale = [](V s, const Vec3& a) { return Vec3{hn::Mul(s, a.x), hn::Mul(s, a.y), hn::Mul(s, a.z)}; };
    auto normalize = [&](const Vec3& a) { return scale(hn::Div(one, hn::Sqrt(dot(a, a))), a); };
    auto select = [](auto m, const Vec3& a, const Vec3& b) {
        return Vec3{hn::IfThenElse(m, a.x, b.x), hn::IfThenElse(m, a.y, b.y), hn::IfThenElse(m, a.z, b.z)};
    };

    for (size_t g = 0; g < count; g += W) {
        const size_t m = std::min(W, count - g);
        const uint8_t* base = blocks + g * bb;
        if (m < W) {
            padded.resize(W * bb);
            std::memcpy(padded.data(), base, m * bb);
            for (size_t l = m; l < W; ++l) std::memcpy(&padded[l * bb], base + (m - 1) * bb, bb);
            base = padded.data();
        }
        int max_points = 0, min_floats = 3 * 64;
        for (size_t l = 0; l < W; ++l) {
            const BlockView block{base + l * bb};
            const auto q = block.anchor_words();
            for (int k = 0; k < 6; ++k) words[k][l] = float(q[k]);
            const int n = l < m ? int(block.point_count()) : 0;
            dst[l] = out, floats[l] = 3 * n, out += 3 * n;
            max_points = std::max(max_points, n), min_floats = std::min(min_floats, 3 * n);
        }
        const V unorm = hn::Set(d, 65535.0f);
        const Vec3 a0{hn::Div(hn::Load(d, words[0]), unorm), hn::Div(hn::Load(d, words[1]), unorm),
                      hn::Div(hn::Load(d, words[2]), unorm)};
        const Vec3 a1{hn::Div(hn::Load(d, words[3]), unorm), hn::Div(hn::Load(d, words[4]), unorm),
                      hn::Div(hn::Load(d, words[5]), unorm)};
        const Vec3 dd{hn::Sub(a1.x, a0.x), hn::Sub(a1.y, a0.y), hn::Sub(a1.z, a0.z)};
        const V n2 = dot(dd, dd);
        const Vec3 axis = select(hn::Lt(zero, n2), scale(hn::Div(one, hn::Sqrt(n2)), dd), Vec3{one, zero, zero});
        const Vec3 helper{hn::Set(d, fiblet::kFrameHelper[0]), hn::Set(d, fiblet::kFrameHelper[1]),
                          hn::Set(d, fiblet::kFrameHelper[2])};
        Vec3 c1 = cross(axis, helper);
        c1 = select(hn::Lt(dot(c1, c1), hn::Set(d, 1e-6f)),
                    cross(axis, Vec3{zero, helper.z, hn::Set(d, -fiblet::kFrameHelper[1])}), c1);
        c1 = normalize(c1);
        const Vec3 c2 = normalize(cross(axis, c1));
        V frame[9] = {axis.x, axis.y, axis.z, c1.x, c1.y, c1.z, c2.x, c2.y, c2.z};

        auto flush = [&](int first) {
            for (int q = 0; q < 3; ++q) {
                V t[kMaxW];
                for (size_t j = 0; j < W; ++j) t[j] = hn::Load(d, rows[q * W + j]);
                Transpose(d, t, W);
                const int at = 3 * first + q * int(W);
                for (size_t l = 0; l < W; ++l) {
                    const int k = std::min(floats[l] - at, int(W));
                    if (k == int(W)) hn::StoreU(t[l], d, dst[l] + at);
                    else if (k > 0) hn::BlendedStore(t[l], hn::FirstN(d, size_t(k)), d, dst[l] + at);
                }
            }
        };
        auto emit = [&](int i, V x, V y, V z) {
            const size_t r = 3 * (size_t(i) % W);
            hn::Store(hn::Sub(hn::Mul(hn::Sub(x, half), scaling), offset[0]), d, rows[r]);
            hn::Store(hn::Sub(hn::Mul(hn::Sub(y, half), scaling), offset[1]), d, rows[r + 1]);
            hn::Store(hn::Sub(hn::Mul(hn::Sub(z, half), scaling), offset[2]), d, rows[r + 2]);
            if (size_t(i) % W == W - 1 || i == max_points - 1) flush(i - int(size_t(i) % W));
        };
        emit(0, a0.x, a0.y, a0.z);
        V p[3] = {a1.x, a1.y, a1.z};
        if (max_points >= 2) emit(1, p[0], p[1], p[2]);
        for (int k = 0; k + 2 < max_points; ++k) {
            for (size_t l = 0; l < W; ++l) code[l] = base[l * bb + fiblet::kBlockDirectionsOffset + size_t(k)];
            const auto idx = hn::Load(di, code);
            V local[kMaxW];
            if constexpr (kRows) {  // W table rows loaded and transposed, as the intrinsics version
                for (size_t l = 0; l < W; ++l) local[l] = hn::Load(d, ctx.frame_rows.data() + 16 * code[l]);
                Transpose(d, local, W);
                if (W < 9) local[8] = hn::GatherIndex(d, soa + 256 * 8, idx);
            } else {
                for (int c = 0; c < 9; ++c) local[c] = hn::GatherIndex(d, soa + 256 * c, idx);
            }
            V next[9];
            for (int j = 0; j < 3; ++j)
                for (int r = 0; r < 3; ++r)
                    next[3 * j + r] = hn::Add(hn::Add(hn::Mul(frame[r], local[3 * j]), hn::Mul(frame[3 + r], local[3 * j + 1])),
                                              hn::Mul(frame[6 + r], local[3 * j + 2]));
            for (int c = 0; c < 9; ++c) frame[c] = next[c];
            for (int r = 0; r < 3; ++r) p[r] = hn::Add(p[r], hn::Mul(step, frame[r]));
            emit(k + 2, p[0], p[1], p[2]);
        }
    }
    return size_t(out - xyz) / 3;
}

size_t DecodeLanesGather(const fiblet::DecodeContext& ctx, const float* soa, const uint8_t* blocks, size_t count,
                         float* xyz) {
    return DecodeLanesT<false>(ctx, soa, blocks, count, xyz);
}
size_t DecodeLanesRows(const fiblet::DecodeContext& ctx, const float* soa, const uint8_t* blocks, size_t count,
                       float* xyz) {
    return DecodeLanesT<true>(ctx, soa, blocks, count, xyz);
}

}  // namespace HWY_NAMESPACE
}  // namespace fiblet_hwy
HWY_AFTER_NAMESPACE();
#endif

#if HWY_ONCE
#include <benchmark/benchmark.h>

#include "bench_fixture.hpp"

namespace {

using Kernel = size_t (*)(const fiblet::DecodeContext&, const float*, const uint8_t*, size_t, float*);

void BM_HighwayLanes(benchmark::State& state, Kernel kernel) {
    const auto& d = fiblet::bench::fixture();
    const fiblet::DecodeContext ctx(d.header);
    std::vector<float> soa(9 * 256);  // component-major, what gathers index
    for (int k = 0; k < 256; ++k)
        for (int c = 0; c < 9; ++c) soa[256 * c + k] = ctx.frame_rows[16 * k + c];
    const size_t bb = d.header.block_bytes(), blocks = d.header.blocks, batch = 512;
    std::vector<float> out(3 * d.header.points_per_block * batch), ref(out.size());
    // Bit for bit the reference on every batch, before timing.
    for (size_t b = 0; b < blocks; b += batch) {
        const size_t n = std::min(batch, blocks - b);
        const size_t got = kernel(ctx, soa.data(), &d.blocks[b * bb], n, out.data());
        const size_t want = fiblet::decode_blocks_scalar(ctx, &d.blocks[b * bb], n, ref.data());
        if (got != want || std::memcmp(out.data(), ref.data(), 12 * got) != 0) {
            state.SkipWithError("Highway lanes decoder differs from the reference");
            return;
        }
    }
    for (auto _ : state) {
        for (size_t b = 0; b < blocks; b += batch) kernel(ctx, soa.data(), &d.blocks[b * bb], std::min(batch, blocks - b), out.data());
        benchmark::DoNotOptimize(out.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(int64_t(state.iterations() * d.points));
}

const int registered = [] {
#if HWY_TARGETS & HWY_AVX2
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
        for (auto [name, kernel] : {std::pair{"HighwayLanes/gather/avx2", &fiblet_hwy::N_AVX2::DecodeLanesGather},
                                    std::pair{"HighwayLanes/rows/avx2", &fiblet_hwy::N_AVX2::DecodeLanesRows}})
            benchmark::RegisterBenchmark(name, BM_HighwayLanes, kernel)->Unit(benchmark::kMillisecond);
#endif
#if HWY_TARGETS & HWY_AVX3
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
        __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl"))
        for (auto [name, kernel] : {std::pair{"HighwayLanes/gather/avx512", &fiblet_hwy::N_AVX3::DecodeLanesGather},
                                    std::pair{"HighwayLanes/rows/avx512", &fiblet_hwy::N_AVX3::DecodeLanesRows}})
            benchmark::RegisterBenchmark(name, BM_HighwayLanes, kernel)->Unit(benchmark::kMillisecond);
#endif
    return 0;
}();

}  // namespace
#endif  // HWY_ONCE
