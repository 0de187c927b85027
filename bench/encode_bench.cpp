// Encoder throughput (points per second on one core): the code search alone
// on fibers already in memory, at each effort level, and the whole
// compress pipeline (.tck on disk -> .fft on disk, one thread).
//
//   build/bench/fiblet_bench --benchmark_filter=Encode
//
// BM_EncodeMetrics: the symmetric error report alone (GeometryError).
//
// Input: FIBLET_BENCH_TCK (default ../shared/data/small-ifod1.tck).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "fiblet/compress.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/geometry_error.hpp"
#include "fiblet/tck.hpp"

namespace {

std::string bench_tck() {
    if (const char* p = std::getenv("FIBLET_BENCH_TCK")) return p;
    return std::string(FIBLET_SHARED_DIR) + "/data/small-ifod1.tck";
}

struct Input {
    std::vector<std::vector<fiblet::Vec3f>> fibers;
    std::size_t points = 0;
    fiblet::CompressReport report;  // the header and search the pipeline chose for it
};

// The input fibers, and what the pipeline chooses for them at this effort.
const Input& input(unsigned bits, int effort) {
    static std::map<std::pair<unsigned, int>, Input> cache;
    Input& in = cache[{bits, effort}];
    if (in.fibers.empty()) {
        fiblet::TckReader r(bench_tck());
        std::vector<fiblet::Vec3f> f;
        while (r.next(f)) in.points += f.size(), in.fibers.push_back(f);
        fiblet::CompressOptions o;
        o.direction_bits = bits;
        o.search = fiblet::search_for_effort(effort);
        o.overwrite = true;
        const std::string tmp = std::filesystem::temp_directory_path() / "fiblet-encode-bench.fft";
        in.report = fiblet::compress_file(bench_tck(), tmp, o);
        std::filesystem::remove(tmp);
    }
    return in;
}

// The encoder as compress runs it (its search, the length tails where
// compress keeps lengths; fixed-step input) on fibers in memory, blocks to
// memory, one thread: the fibers 64 at a time, as compress gives them.
void BM_EncodeSearch(benchmark::State& state) {
    const Input& in = input(unsigned(state.range(0)), int(state.range(1)));
    const fiblet::FiberEncoder encoder =
        fiblet::FiberEncoder(in.report.header, in.report.search).with_length_feedback(in.report.lengths_kept ? 1.0f : 0.0f, true);
    constexpr std::size_t kTogether = 64;
    std::vector<std::span<const fiblet::Vec3f>> fibers(in.fibers.begin(), in.fibers.end());
    std::vector<std::uint8_t> blocks;
    for (auto _ : state) {
        for (std::size_t i = 0; i < fibers.size(); i += kTogether) {
            blocks.clear();
            const std::size_t n = std::min(kTogether, fibers.size() - i);
            encoder.encode_fibers(std::span<const std::span<const fiblet::Vec3f>>(fibers).subspan(i, n), std::uint32_t(i), blocks);
            benchmark::DoNotOptimize(blocks.data());
        }
    }
    state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(in.points));
    state.counters["max_um"] = in.report.error.max_mm() * 1e3;
    state.counters["mean_um"] = in.report.error.mean_mm() * 1e3;
}
BENCHMARK(BM_EncodeSearch)
    ->ArgNames({"bits", "effort"})
    ->ArgsProduct({{8}, {0, 1, 2, 3, 4}})
    ->Args({16, 0})
    ->Args({16, 1})
    ->Unit(benchmark::kMillisecond);

// The symmetric error report compress computes on every point (both ways
// against the polylines, endpoints, lengths), on the default effort's decoded
// fibers, one thread: the share of the pipeline that is not the code search.
void BM_EncodeMetrics(benchmark::State& state) {
    const Input& in = input(8, 1);
    const fiblet::FiberEncoder encoder(in.report.header, in.report.search);
    std::vector<std::vector<fiblet::Vec3f>> decoded(in.fibers.size());
    std::vector<std::uint8_t> blocks;
    for (std::size_t i = 0; i < in.fibers.size(); ++i) encoder.encode(in.fibers[i], std::uint32_t(i), blocks, &decoded[i]);
    for (auto _ : state) {
        fiblet::GeometryError g;
        for (std::size_t i = 0; i < in.fibers.size(); ++i) g.add_fiber(in.fibers[i], decoded[i], i);
        benchmark::DoNotOptimize(g.hausdorff_mm());
    }
    state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(in.points));
}
BENCHMARK(BM_EncodeMetrics)->Unit(benchmark::kMillisecond);

// The whole pipeline (.tck on disk -> .fft on disk), one thread.
void BM_EncodePipeline(benchmark::State& state) {
    const std::string tmp = std::filesystem::temp_directory_path() / "fiblet-encode-bench-pipeline.fft";
    fiblet::CompressOptions o;
    o.overwrite = true;
    o.threads = 1;
    o.search = fiblet::search_for_effort(int(state.range(0)));
    std::uint64_t points = 0;
    for (auto _ : state) points += fiblet::compress_file(bench_tck(), tmp, o).header.points;
    std::filesystem::remove(tmp);
    state.SetItemsProcessed(std::int64_t(points));
}
BENCHMARK(BM_EncodePipeline)->ArgNames({"effort"})->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

}  // namespace
