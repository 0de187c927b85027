// Choosing a decoder: names, what this CPU runs, and decode_blocks (the
// public entry point that validates, picks the kernel and splits the blocks
// across threads).
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "core/thread_count.hpp"
#include "decode/decode_kernels.hpp"
#include "fiblet/parallel.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"

namespace fiblet {

namespace {

// Whether the library was built with kernels of this level.
bool compiled([[maybe_unused]] SimdLevel level) {
#ifdef FIBLET_HAVE_X86_KERNELS
    return true;
#else
    return level == SimdLevel::portable;
#endif
}

bool cpu_has(SimdLevel level) {
#ifdef FIBLET_HAVE_X86_KERNELS
    __builtin_cpu_init();  // needed when called from a static initializer
#endif
    switch (level) {
        case SimdLevel::portable:
            return true;
#ifdef FIBLET_HAVE_X86_KERNELS
        // __builtin_cpu_supports also checks that the OS saves the wider
        // registers (XGETBV), so a feature bit alone is not enough.
        case SimdLevel::avx2:
            return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
        case SimdLevel::avx512:
            return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                   __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl") &&
                   __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#endif
        default:
            return false;
    }
}

SimdLevel best_level() {
    static const SimdLevel best = cpu_has(SimdLevel::avx512) ? SimdLevel::avx512
                                  : cpu_has(SimdLevel::avx2) ? SimdLevel::avx2
                                                             : SimdLevel::portable;
    return best;
}

const detail::KernelSet& kernels(SimdLevel level) {
    switch (level) {
#ifdef FIBLET_HAVE_X86_KERNELS
        case SimdLevel::avx2:
            return detail::avx2::kKernels;
        case SimdLevel::avx512:
            return detail::avx512::kKernels;
#endif
        default:
            return detail::portable::kKernels;
    }
}

const char* kind_name(DecoderKind k) {
    switch (k) {
        case DecoderKind::scalar: return "scalar";
        case DecoderKind::warp: return "warp";
        case DecoderKind::lanes: return "lanes";
        default: return "auto";
    }
}

const char* level_name(SimdLevel s) {
    switch (s) {
        case SimdLevel::portable: return "portable";
        case SimdLevel::avx2: return "avx2";
        case SimdLevel::avx512: return "avx512";
        default: return "best";
    }
}

}  // namespace

namespace {

std::size_t decode_kernel(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count, float* xyz,
                          Decoder d) {
    if (ctx.header.direction_bits() == 16)  // one SIMD decoder for 16-bit blocks: warp runs as lanes
        return d.kind == DecoderKind::scalar ? decode_blocks_scalar16(ctx, blocks, count, xyz)
                                             : kernels(d.simd).lanes16(ctx, blocks, count, xyz);
    switch (d.kind) {
        case DecoderKind::lanes: return kernels(d.simd).lanes(ctx, blocks, count, xyz);
        case DecoderKind::warp: return kernels(d.simd).warp(ctx, blocks, count, xyz);
        default: return decode_blocks_scalar(ctx, blocks, count, xyz);
    }
}

// Every decode of a file's blocks goes through here: the kernel, then the
// fibers' last-step fractions (fiblet/fiber_ends.hpp), while the points are
// still in cache.
std::size_t decode_direct(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count, float* xyz,
                          Decoder d) {
    const std::size_t n = decode_kernel(ctx, blocks, count, xyz, d);
    if (ctx.end_fractions) apply_fiber_ends(ctx.header, *ctx.end_fractions, blocks, count, xyz);
    return n;
}

#ifdef __SSE2__
// Copies n floats with non-temporal stores (no read of the destination's
// cache lines before writing them, no eviction of the working set).
void stream_copy(float* dst, const float* src, std::size_t n) {
    std::size_t head = std::min(n, ((16 - reinterpret_cast<std::uintptr_t>(dst) % 16) % 16) / 4);
    if (reinterpret_cast<std::uintptr_t>(dst) % 4 != 0) head = n;  // not float-aligned: plain copy
    std::memcpy(dst, src, 4 * head);
    std::size_t i = head;
    for (; i + 16 <= n; i += 16) {
        _mm_stream_ps(dst + i, _mm_loadu_ps(src + i));
        _mm_stream_ps(dst + i + 4, _mm_loadu_ps(src + i + 4));
        _mm_stream_ps(dst + i + 8, _mm_loadu_ps(src + i + 8));
        _mm_stream_ps(dst + i + 12, _mm_loadu_ps(src + i + 12));
    }
    std::memcpy(dst + i, src + i, 4 * (n - i));
}
#endif

}  // namespace

std::size_t detail::decode_resolved(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count,
                                    float* xyz, Decoder d) {
#ifdef __SSE2__
    // Output far larger than the caches: written straight to memory, each
    // cache line is first read (write-allocate), doubling the traffic of a
    // memory-bound decoder. Decode batches into a buffer that stays in L2
    // and stream them out instead (bench: DecodeBlocksToMemory).
    constexpr std::size_t kBatchPoints = 256 * 60, kStreamBytes = 4u << 20;  // 180 kB of points a batch
    const std::size_t most = 12 * count * ctx.header.points_per_block;
    if (d.kind != DecoderKind::scalar && most >= kStreamBytes) {
        const std::size_t batch_blocks = std::max<std::size_t>(1, kBatchPoints / ctx.header.points_per_block);
        thread_local std::vector<float> staging;
        staging.resize(3 * batch_blocks * ctx.header.points_per_block);
        const std::size_t bb = ctx.header.block_bytes();
        std::size_t points = 0;
        for (std::size_t b = 0; b < count; b += batch_blocks) {
            const std::size_t n = decode_direct(ctx, blocks + b * bb, std::min(batch_blocks, count - b), staging.data(), d);
            stream_copy(xyz + 3 * points, staging.data(), 3 * n);
            points += n;
        }
        _mm_sfence();  // streamed stores visible before another thread reads them
        return points;
    }
#endif
    return decode_direct(ctx, blocks, count, xyz, d);
}

Decoder parse_decoder(const std::string& name) {
    const std::size_t dash = name.find('-');
    const std::string kind = name.substr(0, dash), level = dash == std::string::npos ? "" : name.substr(dash + 1);
    Decoder d;
    if (kind == "auto" || kind == "automatic") d.kind = DecoderKind::automatic;
    else if (kind == "scalar") d.kind = DecoderKind::scalar;
    else if (kind == "warp") d.kind = DecoderKind::warp;
    else if (kind == "lanes") d.kind = DecoderKind::lanes;
    else throw Error(Errc::invalid_argument, "unknown decoder '" + name + "' (auto, scalar, warp, lanes, or warp/lanes-LEVEL)");
    if (dash == std::string::npos || level == "best") d.simd = SimdLevel::best;
    else if (level == "portable") d.simd = SimdLevel::portable;
    else if (level == "avx2") d.simd = SimdLevel::avx2;
    else if (level == "avx512") d.simd = SimdLevel::avx512;
    else throw Error(Errc::invalid_argument, "unknown SIMD level in decoder '" + name + "' (portable, avx2, avx512)");
    if (d.kind == DecoderKind::scalar && d.simd != SimdLevel::best && d.simd != SimdLevel::portable)
        throw Error(Errc::invalid_argument, "the scalar decoder has no SIMD level: '" + name + "'");
    return d;
}

Decoder resolve_decoder(Decoder d) {
    // The lanes decoder is the fastest wherever SIMD is available
    // (bench/results.md); without SIMD the reference is as fast.
    if (d.kind == DecoderKind::automatic) {
        const SimdLevel level = d.simd == SimdLevel::best ? best_level() : d.simd;
        d.kind = level == SimdLevel::portable ? DecoderKind::scalar : DecoderKind::lanes;
    }
    if (d.kind == DecoderKind::scalar) return {DecoderKind::scalar, SimdLevel::portable};
    if (d.simd == SimdLevel::best) d.simd = best_level();
    if (!cpu_has(d.simd))
        throw Error(Errc::unsupported, std::string("this CPU cannot run the ") + level_name(d.simd) + " decoders");
    return d;
}

std::string decoder_name(Decoder d) {
    d = resolve_decoder(d);
    if (d.kind == DecoderKind::scalar) return "scalar";
    return std::string(kind_name(d.kind)) + "-" + level_name(d.simd);
}

std::vector<std::string> available_decoders() {
    std::vector<std::string> names{decoder_name({})};  // what `auto` picks, first
    auto add = [&](std::string name) {
        if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(std::move(name));
    };
    for (SimdLevel level : {SimdLevel::avx512, SimdLevel::avx2, SimdLevel::portable})
        if (cpu_has(level)) add(std::string("lanes-") + level_name(level));
    add("scalar");
    for (SimdLevel level : {SimdLevel::avx512, SimdLevel::avx2, SimdLevel::portable})
        if (cpu_has(level)) add(std::string("warp-") + level_name(level));
    return names;
}

std::vector<std::string> compiled_decoders() {
    std::vector<std::string> names{"scalar"};
    for (const char* kind : {"lanes-", "warp-"})
        for (SimdLevel level : {SimdLevel::avx512, SimdLevel::avx2, SimdLevel::portable})
            if (compiled(level)) names.push_back(kind + std::string(level_name(level)));
    return names;
}

std::size_t decode_blocks(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count, float* xyz,
                          Decoder decoder, unsigned threads) {
    const Decoder d = resolve_decoder(decoder);
    threads = detail::resolve_threads(threads);
    // Below a few thousand blocks per thread, starting a thread costs more
    // than it saves.
    constexpr std::size_t kMinBlocksPerThread = 2048;
    threads = unsigned(std::clamp<std::size_t>(count / kMinBlocksPerThread, 1, threads));
    if (threads == 1) {
        count_block_points(ctx, blocks, count);
        return detail::decode_resolved(ctx, blocks, count, xyz, d);
    }
    // Contiguous runs of blocks; each run's output starts after the points
    // of the runs before it, so the order never depends on `threads`.
    // Up to 4 runs per thread, handed out one at a time by the pool.
    const std::size_t bb = ctx.header.block_bytes();
    const auto runs = unsigned(std::clamp<std::size_t>(count / (kMinBlocksPerThread / 2), 1, 4 * threads));
    std::vector<std::size_t> first(runs + 1), points(runs + 1, 0);
    for (unsigned t = 0; t <= runs; ++t) first[t] = count * t / runs;
    parallel_for(runs, threads, [&](std::size_t t) {
        points[t + 1] = count_block_points(ctx, blocks + first[t] * bb, first[t + 1] - first[t]);
    });
    for (unsigned t = 0; t < runs; ++t) points[t + 1] += points[t];
    parallel_for(runs, threads, [&](std::size_t t) {
        detail::decode_resolved(ctx, blocks + first[t] * bb, first[t + 1] - first[t], xyz + 3 * points[t], d);
    });
    return points[runs];
}

}  // namespace fiblet
