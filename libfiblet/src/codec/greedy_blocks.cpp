// Greedy aiming, one block per SIMD lane (greedy_blocks.hpp).
//
// Highway compiles the lane code once per x86 target (foreach_target.h);
// the level is chosen here, from the CPU's features, with our own table
// rather than HWY_DYNAMIC_DISPATCH: that needs libhwy's run-time target
// detection, and a static libfiblet would then need -lhwy on every
// downstream link line. Only Highway's headers are used.
#if defined(FIBLET_HAVE_HWY) && defined(__x86_64__)
#define FIBLET_GREEDY_HWY 1
// The targets we dispatch to (plus Highway's baseline, which it always compiles).
#define HWY_DISABLED_TARGETS (HWY_SSSE3 | HWY_AVX3_DL)
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "codec/greedy_blocks.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
//
#include <hwy/highway.h>
#define FIBLET_GREEDY_ONCE HWY_ONCE
#else
#define FIBLET_GREEDY_HWY 0
#define FIBLET_GREEDY_ONCE 1
#endif

#include <atomic>
#include <climits>
#include <cstdlib>
#include <string>

#include "codec/greedy_blocks.hpp"
#include "fiblet/error.hpp"

#if FIBLET_GREEDY_HWY && (HWY_TARGET == HWY_SSE4 || HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3)
HWY_BEFORE_NAMESPACE();
namespace fiblet::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

constexpr std::size_t kMaxLanes = 16;

// Blocks j0 .. j0 + active - 1 of the batch, one per lane of `d` (lanes
// past `active` repeat the last block; their results are dropped).
template <class D>
void GreedyVector(D d, const Codebook8& cb, float step, const GreedyBatch& batch, std::size_t j0, std::size_t active) {
    const hn::RebindToSigned<D> di;
    using VF = hn::Vec<D>;
    using VI = hn::Vec<decltype(di)>;
    const std::size_t lanes = hn::Lanes(d), stride = batch.stride;
    static_assert(sizeof(Frame) == 9 * sizeof(float), "frames are gathered as 9 floats");
    static_assert(sizeof(Vec3f) == 3 * sizeof(float), "points are gathered as 3 floats");
    const float* code_frames = &cb.table.frame(0).c[0].x;
    const NearestCodeLut::Gnomonic g = cb.lut.gnomonic();

    const VF zero = hn::Zero(d), stepv = hn::Set(d, step);
    const VF rim_tan = hn::Set(d, g.rim_tan), rim_tan2 = hn::Set(d, g.rim_tan2), cell_scale = hn::Set(d, g.cell_scale);
    const VF one = hn::Set(d, 1.0f), last_cell = hn::Set(d, float(NearestCodeLut::kGrid - 1));
    const VF int_range = hn::Set(d, 2147483648.0f);
    const VI zero_code = hn::Set(di, g.zero_code), back_code = hn::Set(di, g.back_code);
    const VI last_word = hn::Set(di, NearestCodeLut::kGrid * NearestCodeLut::kGrid - 4), byte = hn::Set(di, 0xff);
    // NearestCodeLut::cell(): int((u + rim_tan) * cell_scale) clamped to [0, kGrid - 1].
    // The scalar conversion (cvttss2si) gives INT_MIN for NaN and for values
    // out of int range, which the clamp turns into 0; Highway's saturates
    // instead, so those lanes are zeroed before converting.
    auto cell = [&](VF u) {
        const VF f = hn::Mul(hn::Add(u, rim_tan), cell_scale);
        const VF in_range = hn::IfThenElseZero(hn::Lt(f, int_range), f);  // NaN, >= 2^31: 0
        return hn::ConvertTo(di, hn::Min(hn::Max(in_range, zero), last_cell));
    };

    // Per lane: its block, its start, and its last target's float index
    // (3 * (lane's offset + m - 1), relative to block j0's targets).
    alignas(64) float start[12][kMaxLanes];
    alignas(64) std::int32_t first_at[kMaxLanes], last_at[kMaxLanes];
    std::size_t m_of[kMaxLanes], steps = 0;
    for (std::size_t i = 0; i < lanes; ++i) {
        const std::size_t j = j0 + std::min(i, active - 1);
        const Frame& fr = batch.frames[j];
        const Vec3f& p = batch.starts[j * stride];
        for (int c = 0; c < 3; ++c)
            start[3 * c][i] = fr.c[c].x, start[3 * c + 1][i] = fr.c[c].y, start[3 * c + 2][i] = fr.c[c].z;
        start[9][i] = p.x, start[10][i] = p.y, start[11][i] = p.z;
        m_of[i] = j + 1 == batch.blocks ? batch.last_m : batch.m;
        steps = std::max(steps, m_of[i]);
        first_at[i] = std::int32_t(3 * (j - j0) * stride);
        last_at[i] = std::int32_t(3 * ((j - j0) * stride + m_of[i] - 1));
    }
    // f[3 * c + i]: component i of the frame's column c, one block per lane.
    VF f[9];
    for (int j = 0; j < 9; ++j) f[j] = hn::Load(d, start[j]);
    VF px = hn::Load(d, start[9]), py = hn::Load(d, start[10]), pz = hn::Load(d, start[11]);
    const float* targets = &batch.targets[j0 * stride].x;
    // Lane i's target k at float index first_at[i] + 3 k, held at its last
    // target once its block is done (a shorter last block).
    VI at = hn::Load(di, first_at);
    const VI at_end = hn::Load(di, last_at), three = hn::Set(di, 3);
    // Where each active lane writes; the lanes whose block is done by step k drop out.
    Vec3f* decoded[kMaxLanes];
    std::uint8_t* codes[kMaxLanes];
    for (std::size_t i = 0; i < active; ++i)
        decoded[i] = batch.decoded + (j0 + i) * stride, codes[i] = batch.codes + (j0 + i) * batch.code_stride;
    alignas(64) float out[3][kMaxLanes];
    alignas(64) std::int32_t out_code[kMaxLanes];
    for (std::size_t k = 0; k < steps; ++k) {
        // apply_transposed(f, t - p): dot(c_j, v) = (c_j.x v.x + c_j.y v.y) + c_j.z v.z.
        const VF vx = hn::Sub(hn::GatherIndex(d, targets, at), px);
        const VF vy = hn::Sub(hn::GatherIndex(d, targets + 1, at), py);
        const VF vz = hn::Sub(hn::GatherIndex(d, targets + 2, at), pz);
        auto dot_v = [&](int c) {
            return hn::Add(hn::Add(hn::Mul(f[3 * c], vx), hn::Mul(f[3 * c + 1], vy)), hn::Mul(f[3 * c + 2], vz));
        };
        const VF x = dot_v(0), y = dot_v(1), z = dot_v(2);

        // NearestCodeLut::operator(): both the cap's and the rim's (u, v), then per lane the one it takes.
        const VF lateral2 = hn::Add(hn::Mul(y, y), hn::Mul(z, z));
        const auto in_cap = hn::And(hn::Gt(x, zero), hn::Le(lateral2, hn::Mul(rim_tan2, hn::Mul(x, x))));
        const VF inv = hn::Div(one, x);
        VF u = hn::Mul(y, inv), v = hn::Mul(z, inv);
        // The rim's square root and division only when a lane needs them
        // (rare: they would lengthen every step's dependency chain).
        if (!hn::AllTrue(d, in_cap)) {
            const VF s = hn::Div(rim_tan, hn::Sqrt(lateral2));
            u = hn::IfThenElse(in_cap, u, hn::Mul(y, s));
            v = hn::IfThenElse(in_cap, v, hn::Mul(z, s));
        }
        const VI index = hn::Add(hn::ShiftLeft<8>(cell(u)), cell(v));
        // The cell's byte: a 32-bit gather at its offset, moved back from
        // the table's last 3 bytes so that it never reads past the end.
        const VI word_at = hn::Min(index, last_word);
        const VI word = hn::GatherOffset(di, reinterpret_cast<const std::int32_t*>(g.cells), word_at);
        const VI looked_up = hn::And(word >> hn::ShiftLeft<3>(hn::Sub(index, word_at)), byte);
        // Outside the cap with no lateral direction: straight back or the zero vector's code.
        const auto no_lateral = hn::RebindMask(di, hn::AndNot(in_cap, hn::Not(hn::Gt(lateral2, zero))));
        const VI behind = hn::IfThenElse(hn::RebindMask(di, hn::Lt(x, zero)), back_code, zero_code);
        const VI code = hn::IfThenElse(no_lateral, behind, looked_up);

        // compose(f, frame(code)): column c of the new frame is
        // apply(f, L.c_c) = (f.c0 L.x + f.c1 L.y) + f.c2 L.z, per component.
        const VI at_frame = hn::Add(hn::ShiftLeft<3>(code), code);  // code * 9
        VF l[9];
        for (int j = 0; j < 9; ++j) l[j] = hn::GatherIndex(d, code_frames + j, at_frame);
        VF nf[9];
        for (int c = 0; c < 3; ++c)
            for (int i = 0; i < 3; ++i)
                nf[3 * c + i] = hn::Add(hn::Add(hn::Mul(f[i], l[3 * c]), hn::Mul(f[3 + i], l[3 * c + 1])),
                                        hn::Mul(f[6 + i], l[3 * c + 2]));
        for (int j = 0; j < 9; ++j) f[j] = nf[j];
        // p + step * f.c0
        px = hn::Add(px, hn::Mul(stepv, f[0]));
        py = hn::Add(py, hn::Mul(stepv, f[1]));
        pz = hn::Add(pz, hn::Mul(stepv, f[2]));

        at = hn::Min(hn::Add(at, three), at_end);
        // The step's results to their blocks: scalar stores, which the CPU
        // overlaps with the next step's dependency chain.
        hn::Store(px, d, out[0]);
        hn::Store(py, d, out[1]);
        hn::Store(pz, d, out[2]);
        hn::Store(code, di, out_code);
        for (std::size_t i = 0; i < active; ++i) {
            if (k >= m_of[i]) continue;
            decoded[i][k] = {out[0][i], out[1][i], out[2][i]};
            codes[i][k] = std::uint8_t(out_code[i]);
        }
    }
}

// Blocks [0, n) of the batch in vectors: full ones of the widest width,
// then the rest in the narrowest width that holds it (at least 2 blocks
// a vector); returns n (the few left are the scalar search's).
std::size_t GreedyVectors(const Codebook8& cb, float step, const GreedyBatch& batch) {
    const hn::ScalableTag<float> d;
    const std::size_t lanes = hn::Lanes(d);
    std::size_t j = 0;
    for (; j + lanes <= batch.blocks; j += lanes) GreedyVector(d, cb, step, batch, j, lanes);
    const std::size_t left = batch.blocks - j;
    if (left < 2) return j;
#if HWY_TARGET == HWY_AVX3
    if (left > 8) GreedyVector(d, cb, step, batch, j, left);
    else if (left > 4) GreedyVector(hn::CappedTag<float, 8>(), cb, step, batch, j, left);
    else GreedyVector(hn::CappedTag<float, 4>(), cb, step, batch, j, left);
#elif HWY_TARGET == HWY_AVX2
    if (left > 4) GreedyVector(d, cb, step, batch, j, left);
    else GreedyVector(hn::CappedTag<float, 4>(), cb, step, batch, j, left);
#else
    GreedyVector(d, cb, step, batch, j, left);
#endif
    return batch.blocks;
}

}  // namespace fiblet::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();
#endif

#if FIBLET_GREEDY_ONCE
#if FIBLET_GREEDY_HWY
#include <cpuid.h>
#endif

namespace fiblet::detail {
namespace {

using VectorSearch = std::size_t (*)(const Codebook8&, float, const GreedyBatch&);

constexpr SimdLevel kLevels[] = {SimdLevel::scalar, SimdLevel::sse4, SimdLevel::avx2, SimdLevel::avx512};

void require_supported(SimdLevel level) {
    if (!simd_level_supported(level))
        throw Error(Errc::invalid_argument, std::string("SIMD level ") + simd_level_name(level) +
                                                ": this CPU or build does not support it");
}

VectorSearch vector_search(SimdLevel level) {
    switch (level) {
#if FIBLET_GREEDY_HWY && (HWY_TARGETS & HWY_AVX3)
        case SimdLevel::avx512: return &N_AVX3::GreedyVectors;
#endif
#if FIBLET_GREEDY_HWY && (HWY_TARGETS & HWY_AVX2)
        case SimdLevel::avx2: return &N_AVX2::GreedyVectors;
#endif
#if FIBLET_GREEDY_HWY && (HWY_TARGETS & HWY_SSE4)
        case SimdLevel::sse4: return &N_SSE4::GreedyVectors;
#endif
        default: return nullptr;
    }
}

// The CPU features Highway's targets are compiled for (hwy/ops/set_macros-inl.h,
// HWY_TARGET_STR_*); __builtin_cpu_supports also checks that the OS saves the
// wide registers.
#if FIBLET_GREEDY_HWY
// CPUID.1:ECX.F16C (clang's __builtin_cpu_supports does not know "f16c").
bool has_f16c() {
    unsigned a = 0, b = 0, c = 0, d = 0;
    return __get_cpuid(1, &a, &b, &c, &d) && (c & bit_F16C) != 0;
}
#endif

bool detect(SimdLevel level) {
#if FIBLET_GREEDY_HWY
    __builtin_cpu_init();
    const bool sse4 = __builtin_cpu_supports("ssse3") && __builtin_cpu_supports("sse4.1") &&
                      __builtin_cpu_supports("sse4.2") && __builtin_cpu_supports("pclmul") && __builtin_cpu_supports("aes");
    const bool avx2 = sse4 && __builtin_cpu_supports("avx") && __builtin_cpu_supports("avx2") &&
                      __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") && __builtin_cpu_supports("fma") &&
                      has_f16c();
    const bool avx512 = avx2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                        __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw");
    switch (level) {
        case SimdLevel::scalar: return true;
        case SimdLevel::sse4: return sse4;
        case SimdLevel::avx2: return avx2;
        case SimdLevel::avx512: return avx512;
    }
    return false;
#else
    return level == SimdLevel::scalar;
#endif
}

bool cpu_supports(SimdLevel level) {
    static const bool supported[4] = {detect(SimdLevel::scalar), detect(SimdLevel::sse4), detect(SimdLevel::avx2),
                                      detect(SimdLevel::avx512)};
    return supported[int(level)];
}

SimdLevel widest_supported() {
    for (SimdLevel l : {SimdLevel::avx512, SimdLevel::avx2, SimdLevel::sse4})
        if (simd_level_supported(l)) return l;
    return SimdLevel::scalar;
}

// FIBLET_SIMD, read once: a level, or the error to report.
struct EnvironmentChoice {
    std::optional<SimdLevel> level;
    std::string error;
};

const EnvironmentChoice& environment_choice() {
    static const EnvironmentChoice choice = [] {
        EnvironmentChoice c;
        const char* value = std::getenv("FIBLET_SIMD");
        if (!value || !*value) return c;
        const std::optional<SimdLevel> level = parse_simd_level(value);
        if (!level)
            c.error = std::string("FIBLET_SIMD=") + value + ": unknown level (use avx512, avx2, sse4 or scalar)";
        else if (!simd_level_supported(*level))
            c.error = std::string("FIBLET_SIMD=") + value + ": this CPU or build does not support it";
        else
            c.level = level;
        return c;
    }();
    return choice;
}

std::atomic<int> forced_level{-1};

// search_codes' greedy for blocks [first, batch.blocks): four in lockstep, then one at a time.
void scalar_blocks(const Codebook8& cb, float step, const GreedyBatch& batch, std::size_t first) {
    constexpr int kLanes = 4;
    const std::size_t same_length = batch.last_m == batch.m ? batch.blocks : batch.blocks - 1;
    std::size_t j = first;
    for (; j + kLanes <= same_length; j += kLanes) {
        GreedyLanes<Codebook8, kLanes> lanes;
        for (int i = 0; i < kLanes; ++i) {
            const std::size_t at = (j + i) * batch.stride;
            lanes.f[i] = batch.frames[j + i];
            lanes.p[i] = batch.starts[at];
            lanes.targets[i] = batch.targets + at;
            lanes.codes[i] = batch.codes + (j + i) * batch.code_stride;
            lanes.decoded[i] = batch.decoded + at;
        }
        lanes.run(cb, step, batch.m);
    }
    for (; j < batch.blocks; ++j) {
        const std::size_t at = j * batch.stride;
        search_codes(cb, SearchParams{1, 1}, batch.frames[j], batch.starts[at], step,
                     std::span<const Vec3f>(batch.targets + at, j + 1 == batch.blocks ? batch.last_m : batch.m),
                     batch.codes + j * batch.code_stride, batch.decoded + at);
    }
}

}  // namespace

const char* simd_level_name(SimdLevel level) {
    switch (level) {
        case SimdLevel::scalar: return "scalar";
        case SimdLevel::sse4: return "sse4";
        case SimdLevel::avx2: return "avx2";
        case SimdLevel::avx512: return "avx512";
    }
    return "?";
}

std::optional<SimdLevel> parse_simd_level(std::string_view name) {
    for (SimdLevel l : kLevels)
        if (name == simd_level_name(l)) return l;
    return std::nullopt;
}

bool simd_level_supported(SimdLevel level) {
    return (level == SimdLevel::scalar || vector_search(level) != nullptr) && cpu_supports(level);
}

std::vector<SimdLevel> supported_simd_levels() {
    std::vector<SimdLevel> out;
    for (SimdLevel l : kLevels)
        if (simd_level_supported(l)) out.push_back(l);
    return out;
}

SimdLevel simd_level() {
    if (const int forced = forced_level.load(std::memory_order_relaxed); forced >= 0) return SimdLevel(forced);
    const EnvironmentChoice& env = environment_choice();
    if (!env.error.empty()) throw Error(Errc::invalid_argument, env.error);
    if (env.level) return *env.level;
    static const SimdLevel widest = widest_supported();
    return widest;
}

void force_simd_level(std::optional<SimdLevel> level) {
    if (level) require_supported(*level);
    forced_level.store(level ? int(*level) : -1, std::memory_order_relaxed);
}

void greedy_blocks(const Codebook8& cb, float step, const GreedyBatch& batch) {
    greedy_blocks(cb, step, batch, simd_level());
}

void greedy_blocks(const Codebook8& cb, float step, const GreedyBatch& batch, SimdLevel level) {
    require_supported(level);
    if (batch.blocks == 0) return;
    std::size_t done = 0;
    // The lanes address a vector's points with 32-bit offsets (3 floats a point).
    const bool offsets_fit = batch.stride <= std::size_t(INT_MAX) / 3 / 32 && batch.m <= batch.stride;
    const bool lengths = batch.m > 0 && batch.last_m > 0 && batch.last_m <= batch.m;
    if (const VectorSearch search = vector_search(level); search && cb.lut.usable() && lengths && offsets_fit)
        done = search(cb, step, batch);
    scalar_blocks(cb, step, batch, done);
}

}  // namespace fiblet::detail
#endif
