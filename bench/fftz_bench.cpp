// Decode cost of the seekable zstd container against the plain .fft: the
// whole file in fiber order, and random single fibers (random access reads
// one zstd frame per fiber).
//
//   build/bench/fiblet_bench --benchmark_filter=Fftz
//
// Input: FIBLET_BENCH_TCK (default ../shared/data/small-ifod1.tck).
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <random>
#include <string>

#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/fft_file.hpp"

namespace {

std::string source_tck() {
    if (const char* p = std::getenv("FIBLET_BENCH_TCK")) return p;
    return std::string(FIBLET_SHARED_DIR) + "/data/small-ifod1.tck";
}

// 0: plain .fft; 1: .fftz with transposed groups; 2: .fftz with plain groups.
const std::string& file_for(int kind) {
    static std::map<int, std::string> paths;
    auto it = paths.find(kind);
    if (it == paths.end()) {
        const std::string path = (std::filesystem::temp_directory_path() /
                                  ("fiblet-fftz-bench-" + std::to_string(kind) + (kind ? ".fftz" : ".fft")))
                                     .string();
        fiblet::CompressOptions o;
        o.overwrite = true;
        if (kind) o.zstd = fiblet::ZstdOptions{fiblet::ZstdOptions{}.level, fiblet::ZstdOptions{}.group_blocks, kind == 1};
        fiblet::compress_file(source_tck(), path, o);
        it = paths.emplace(kind, path).first;
    }
    return it->second;
}

void BM_FftzDecodeAll(benchmark::State& state) {
    const fiblet::FftFile file(file_for(int(state.range(0))));
    std::uint64_t points = 0;
    for (auto _ : state)
        fiblet::decode_file(file, [&](std::uint64_t, const fiblet::Streamlines& s) { points += s.point_count(); });
    state.SetItemsProcessed(std::int64_t(points));
    state.counters["bytes"] = double(file.file_size());
}
BENCHMARK(BM_FftzDecodeAll)->ArgNames({"container"})->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

void BM_FftzRandomFiber(benchmark::State& state) {
    const fiblet::FftFile file(file_for(int(state.range(0))));
    std::mt19937_64 rng(1);
    std::uint64_t points = 0;
    for (auto _ : state) {
        const std::uint64_t f = rng() % file.header().fibers;
        points += fiblet::decode_fibers(file, f, f + 1).point_count();
    }
    state.SetItemsProcessed(std::int64_t(points));
}
BENCHMARK(BM_FftzRandomFiber)->ArgNames({"container"})->DenseRange(0, 2)->Unit(benchmark::kMicrosecond);

}  // namespace
