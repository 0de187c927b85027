// Choosing a decoder: names, what this CPU runs, and decode_blocks (the
// public entry point that validates, picks the kernel and splits the blocks
// across threads).
#include <algorithm>
#include <string>
#include <thread>
#include <vector>

#include "decode/decode_kernels.hpp"
#include "decode/parallel_runs.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"

namespace fiblet {

namespace {

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

std::size_t detail::decode_resolved(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count,
                                    float* xyz, Decoder d) {
    switch (d.kind) {
        case DecoderKind::lanes: return kernels(d.simd).lanes(ctx, blocks, count, xyz);
        case DecoderKind::warp: return kernels(d.simd).warp(ctx, blocks, count, xyz);
        default: return decode_blocks_scalar(ctx, blocks, count, xyz);
    }
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
    std::vector<std::string> names;
    for (SimdLevel level : {SimdLevel::avx512, SimdLevel::avx2, SimdLevel::portable})
        if (cpu_has(level)) names.push_back(std::string("lanes-") + level_name(level));
    names.push_back("scalar");
    for (SimdLevel level : {SimdLevel::avx512, SimdLevel::avx2, SimdLevel::portable})
        if (cpu_has(level)) names.push_back(std::string("warp-") + level_name(level));
    return names;
}

std::size_t decode_blocks(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count, float* xyz,
                          Decoder decoder, unsigned threads) {
    const Decoder d = resolve_decoder(decoder);
    if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
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
    const std::size_t bb = ctx.header.block_bytes();
    std::vector<std::size_t> first(threads + 1), points(threads + 1, 0);
    for (unsigned t = 0; t <= threads; ++t) first[t] = count * t / threads;
    detail::parallel_runs(threads, [&](unsigned t) {
        points[t + 1] = count_block_points(ctx, blocks + first[t] * bb, first[t + 1] - first[t]);
    });
    for (unsigned t = 0; t < threads; ++t) points[t + 1] += points[t];
    detail::parallel_runs(threads, [&](unsigned t) {
        detail::decode_resolved(ctx, blocks + first[t] * bb, first[t + 1] - first[t], xyz + 3 * points[t], d);
    });
    return points[threads];
}

}  // namespace fiblet
