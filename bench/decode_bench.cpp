// Micro-benchmarks of decoding and of what it is compared with: every
// decoder on the blocks of a real tractogram in memory (points/s, 1 and 2
// threads), the LUT build, decoding straight from the file, encoding, .tck
// parsing, float16 positions and the sequential decoder without blocks.
// Data: ../shared/data/small-ifod1.tck (or $FIBLET_BENCH_TCK), compressed
// into a temporary directory at start.
#include <benchmark/benchmark.h>
#include <stdlib.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bench_data.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/fft_file.hpp"

namespace fb = fiblet::bench;
using namespace fiblet;

namespace {

struct Data {
    std::string dir, tck, fft;
    fb::Tractogram tractogram;
    FftHeader header;
    std::vector<std::uint8_t> blocks;
    std::size_t points = 0;

    Data() : tck(fb::default_bench_tck()) {
        std::string tmpl = std::filesystem::temp_directory_path().string() + "/fiblet-bench-XXXXXX";
        if (!::mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
        dir = tmpl;
        fft = dir + "/bench.fft";
        compress_tck(tck, fft, {});
        fb::read_tck(tck, tractogram);
        const FftFile file(fft);
        header = file.header();
        blocks = file.read_blocks(0, header.blocks);
        points = header.points;
    }
    ~Data() {
        std::error_code ec;
        std::filesystem::remove_all(dir, ec);
    }
};

const Data& data() {
    static const Data d;
    return d;
}

void set_points(benchmark::State& state, std::size_t points_per_iteration) {
    state.SetItemsProcessed(std::int64_t(state.iterations() * points_per_iteration));
    state.counters["points"] = double(points_per_iteration);
}

// Decodes the file's blocks a batch at a time into a buffer that stays in
// the cache (`batch` blocks, 0 = all at once: output to memory).
void BM_DecodeBlocks(benchmark::State& state, const std::string& name, unsigned threads, std::size_t batch) {
    const Data& d = data();
    const DecodeContext ctx(d.header);
    const Decoder decoder = parse_decoder(name);
    const std::size_t bb = d.header.block_bytes(), blocks = d.header.blocks;
    if (batch == 0) batch = blocks;
    std::vector<float> out(3 * std::size_t(d.header.points_per_block) * batch);
    for (auto _ : state) {
        for (std::size_t b = 0; b < blocks; b += batch)
            decode_blocks(ctx, &d.blocks[b * bb], std::min(batch, blocks - b), out.data(), decoder, threads);
        benchmark::DoNotOptimize(out.data());
        benchmark::ClobberMemory();
    }
    set_points(state, d.points);
    state.counters["blocks/s"] =
        benchmark::Counter(double(state.iterations()) * d.header.blocks, benchmark::Counter::kIsRate);
}

void BM_DecodeFile(benchmark::State& state, const std::string& name, unsigned threads) {
    const Data& d = data();
    const FftFile file(d.fft);
    DecodeOptions o;
    o.decoder = parse_decoder(name);
    o.threads = threads;
    std::vector<float> xyz(3 * d.points);
    std::vector<std::uint64_t> offsets(d.header.fibers + 1);
    for (auto _ : state) {
        decode_fibers_into(file, 0, d.header.fibers, xyz, offsets, o);
        benchmark::ClobberMemory();
    }
    set_points(state, d.points);
}

void BM_BuildDecodeContext(benchmark::State& state) {
    const Data& d = data();
    for (auto _ : state) {
        auto ctx = std::make_unique<DecodeContext>(d.header);
        benchmark::DoNotOptimize(ctx.get());
    }
}

void BM_EncodeFibers(benchmark::State& state) {
    const Data& d = data();
    const FiberEncoder encoder(d.header);
    const fb::Tractogram& t = d.tractogram;
    std::vector<std::uint8_t> out;
    out.reserve(d.blocks.size());
    for (auto _ : state) {
        out.clear();
        for (std::size_t f = 0; f < t.fibers(); ++f) {
            const auto* p = reinterpret_cast<const Vec3f*>(&t.xyz[3 * t.offsets[f]]);
            encoder.encode({p, t.offsets[f + 1] - t.offsets[f]}, std::uint32_t(f), out);
        }
        benchmark::DoNotOptimize(out.data());
    }
    set_points(state, t.points());
    state.counters["blocks/s"] =
        benchmark::Counter(double(state.iterations()) * d.header.blocks, benchmark::Counter::kIsRate);
}

void BM_TckParse(benchmark::State& state) {
    const Data& d = data();
    fb::Tractogram t;
    fb::read_tck(d.tck, t);  // warm: storage allocated, file in the page cache
    for (auto _ : state) {
        fb::read_tck(d.tck, t);
        benchmark::DoNotOptimize(t.xyz.data());
    }
    set_points(state, t.points());
}

void BM_Float16Decode(benchmark::State& state) {
    const fb::Tractogram& t = data().tractogram;
    std::vector<std::uint16_t> half(t.xyz.size());
    fb::to_half(t.xyz.data(), half.data(), t.xyz.size());
    std::vector<float> out(t.xyz.size());
    for (auto _ : state) {
        fb::from_half(half.data(), out.data(), half.size());
        benchmark::DoNotOptimize(out.data());
    }
    set_points(state, t.points());
}

void BM_SequentialDecodeWithoutBlocks(benchmark::State& state) {
    const fb::Tractogram& t = data().tractogram;
    const fb::SequentialCoded coded = fb::encode_sequential(t);
    std::vector<float> out(3 * coded.points);
    for (auto _ : state) {
        fb::decode_sequential(coded, out.data());
        benchmark::DoNotOptimize(out.data());
    }
    set_points(state, t.points());
}

const int registered = [] {
    // Per-block decoding: batches of 512 blocks (360 KiB of points, in L2).
    for (const std::string& name : available_decoders())
        benchmark::RegisterBenchmark(("DecodeBlocks/" + name).c_str(), BM_DecodeBlocks, name, 1u, 512)
            ->Unit(benchmark::kMillisecond);
    // The whole file's points at once (22 MB written to memory).
    for (const std::string& name : {decoder_name({}), std::string("scalar")}) {
        benchmark::RegisterBenchmark(("DecodeBlocksToMemory/" + name).c_str(), BM_DecodeBlocks, name, 1u, 0)
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("DecodeBlocksToMemory/" + name + "/threads:2").c_str(), BM_DecodeBlocks, name,
                                     2u, 0)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
    }
    for (unsigned threads : {1u, 2u})
        benchmark::RegisterBenchmark(("DecodeFile/" + decoder_name({}) + "/threads:" + std::to_string(threads)).c_str(),
                                     BM_DecodeFile, decoder_name({}), threads)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
    benchmark::RegisterBenchmark("BuildDecodeContext", BM_BuildDecodeContext)->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark("EncodeFibers", BM_EncodeFibers)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("TckParse", BM_TckParse)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("Float16Decode", BM_Float16Decode)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("SequentialDecodeWithoutBlocks", BM_SequentialDecodeWithoutBlocks)
        ->Unit(benchmark::kMillisecond);
    return 0;
}();

}  // namespace
