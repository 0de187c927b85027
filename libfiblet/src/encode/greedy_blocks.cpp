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
#define HWY_TARGET_INCLUDE "encode/greedy_blocks.cpp"
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

#include "encode/greedy_blocks.hpp"
#include "fiblet/error.hpp"

#if FIBLET_GREEDY_HWY && (HWY_TARGET == HWY_SSE4 || HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3)
#include "encode/code_lanes-inl.hpp"

HWY_BEFORE_NAMESPACE();
namespace fiblet::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Blocks j0 .. j0 + active - 1 of the batch, one per lane of `d`.
template <class D>
void GreedyVector(D, const Codebook8& cb, float step, const GreedyBatch& batch, std::size_t j0, std::size_t active) {
    using Lanes = CodeLanes<D>;
    using VF = typename Lanes::VF;
    const Lanes code(cb);
    BatchLanes<D> s(batch, j0, active);
    const VF stepv = hn::Set(s.d, step);
    for (std::size_t k = 0; k < s.steps; ++k) {
        VF tx, ty, tz, x, y, z;
        s.target(s.at, tx, ty, tz);
        Lanes::local(s.f, hn::Sub(tx, s.px), hn::Sub(ty, s.py), hn::Sub(tz, s.pz), x, y, z);
        const auto code_k = code.nearest(x, y, z);
        VF l[9], nf[9];
        code.frame(code_k, l);
        Lanes::compose(s.f, l, nf);
        for (int j = 0; j < 9; ++j) s.f[j] = nf[j];
        // p + step * f.c0
        s.px = hn::Add(s.px, hn::Mul(stepv, s.f[0]));
        s.py = hn::Add(s.py, hn::Mul(stepv, s.f[1]));
        s.pz = hn::Add(s.pz, hn::Mul(stepv, s.f[2]));
        s.store(k, code_k);
    }
}

std::size_t GreedyVectors(const Codebook8& cb, float step, const GreedyBatch& batch) {
    return AllVectors(cb, step, batch, [](auto d, auto&&... args) { GreedyVector(d, args...); });
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

constexpr SimdLevel kLevels[] = {SimdLevel::scalar, SimdLevel::sse4, SimdLevel::avx2, SimdLevel::avx512};

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

// search_codes' greedy for blocks [first, batch.blocks): four of the same
// length in lockstep, the others one at a time.
void scalar_blocks(const Codebook8& cb, float step, const GreedyBatch& batch, std::size_t first) {
    constexpr int kLanes = 4;
    for (std::size_t j = first; j < batch.blocks;) {
        const std::size_t m = batch.length(j);
        if (j + kLanes <= batch.blocks && batch.length(j + 1) == m && batch.length(j + 2) == m && batch.length(j + 3) == m) {
            GreedyLanes<Codebook8, kLanes> lanes;
            for (int i = 0; i < kLanes; ++i) {
                const std::size_t at = (j + i) * batch.stride;
                lanes.f[i] = batch.frames[j + i];
                lanes.p[i] = batch.starts[at];
                lanes.targets[i] = batch.targets + at;
                lanes.codes[i] = batch.codes + (j + i) * batch.code_stride;
                lanes.decoded[i] = batch.decoded + at;
            }
            lanes.run(cb, step, m);
            j += kLanes;
            continue;
        }
        const std::size_t at = j * batch.stride;
        search_codes(cb, SearchParams{1, 1}, batch.frames[j], batch.starts[at], step,
                     std::span<const Vec3f>(batch.targets + at, m), batch.codes + j * batch.code_stride, batch.decoded + at);
        ++j;
    }
}

}  // namespace

bool lanes_can_take(const Codebook8& cb, const GreedyBatch& batch) {
    // The lanes address a vector's points with 32-bit offsets (3 floats a point).
    const bool offsets_fit = batch.stride <= std::size_t(INT_MAX) / 3 / 32 && batch.m <= batch.stride;
    bool lengths = batch.m > 0 && batch.last_m > 0 && batch.last_m <= batch.m;
    for (std::size_t j = 0; batch.lengths && j < batch.blocks; ++j) lengths = lengths && batch.lengths[j] > 0 && batch.lengths[j] <= batch.m;
    return cb.lut.usable() && lengths && offsets_fit;
}

void require_simd_level(SimdLevel level) {
    if (!simd_level_supported(level))
        throw Error(Errc::invalid_argument, std::string("SIMD level ") + simd_level_name(level) +
                                                ": this CPU or build does not support it");
}

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
    if (level) require_simd_level(*level);
    forced_level.store(level ? int(*level) : -1, std::memory_order_relaxed);
}

void greedy_blocks(const Codebook8& cb, float step, const GreedyBatch& batch) {
    greedy_blocks(cb, step, batch, simd_level());
}

void greedy_blocks(const Codebook8& cb, float step, const GreedyBatch& batch, SimdLevel level) {
    require_simd_level(level);
    if (batch.blocks == 0) return;
    std::size_t done = 0;
    if (const VectorSearch search = vector_search(level); search && lanes_can_take(cb, batch)) done = search(cb, step, batch);
    scalar_blocks(cb, step, batch, done);
}

}  // namespace fiblet::detail
#endif
