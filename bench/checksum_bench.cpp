// What integrity checking costs: XXH64 alone, and decoding a whole file with
// and without verifying its checksums (the block structure is checked both
// ways). The input is a synthetic ~60 MB tractogram, made once per run in a
// temporary directory.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "fiblet/checksum.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"

namespace {

// A compressed synthetic tractogram (5 M points), made on first use in a
// directory removed at exit.
const std::string& sample_fft() {
    struct Dir {
        std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("fiblet-checksum-bench-" + std::to_string(std::random_device{}()));
        ~Dir() { std::filesystem::remove_all(path); }
    };
    static const Dir holder;
    static const std::string path = [] {
        const std::filesystem::path& dir = holder.path;
        std::filesystem::create_directories(dir);
        const std::string tck = (dir / "in.tck").string(), fft = (dir / "in.fft").string();
        std::mt19937_64 rng(1);
        std::uniform_real_distribution<double> u(-1, 1);
        fiblet::TckWriter w(tck, {}, true);
        std::vector<fiblet::Vec3f> f(100);
        for (int i = 0; i < 50000; ++i) {
            double p[3] = {30 * u(rng), 30 * u(rng), 30 * u(rng)}, d[3] = {u(rng), u(rng), u(rng) + 1e-6};
            for (auto& q : f) {
                q = {float(p[0]), float(p[1]), float(p[2])};
                double n = 0;
                for (int a = 0; a < 3; ++a) d[a] += 0.02 * u(rng) - 0.001 * p[a], n += d[a] * d[a];
                for (int a = 0; a < 3; ++a) d[a] /= std::sqrt(n), p[a] += 0.1 * d[a];
            }
            w.write(f);
        }
        w.finish();
        fiblet::CompressOptions o;
        o.overwrite = true;
        fiblet::compress_file(tck, fft, o);
        std::filesystem::remove(tck);
        return fft;
    }();
    return path;
}

void BM_Xxh64(benchmark::State& state) {
    std::vector<std::uint8_t> data(std::size_t(state.range(0)), 7);
    for (auto _ : state) benchmark::DoNotOptimize(fiblet::xxh64(data.data(), data.size()));
    state.SetBytesProcessed(std::int64_t(state.iterations()) * state.range(0));
}
BENCHMARK(BM_Xxh64)->Arg(76 * 1024)->Arg(4 << 20);

// Decoding the whole file (decode_file, default options), checksums verified or not.
void BM_DecodeFile(benchmark::State& state) {
    const bool verify = state.range(0) != 0;
    const std::string& path = sample_fft();  // made once, before the timing
    std::uint64_t points = 0;
    for (auto _ : state) {
        const fiblet::FftFile f(path, {.verify_checksums = verify});
        fiblet::decode_file(f, [&](std::uint64_t, const fiblet::Streamlines& s) { points += s.point_count(); });
    }
    state.SetItemsProcessed(std::int64_t(points));
    state.SetLabel(verify ? "checksums verified" : "structure only");
}
BENCHMARK(BM_DecodeFile)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
