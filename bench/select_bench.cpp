// Selective decoding on the medium tractogram: the time of queries keeping
// about 1 %, 10 % and 50 % of the blocks against a full decode, and the
// index's size and load/compute times.
//
// Data: $FIBLET_BENCH_DATA (default: bench-data/ next to the build's bench/
// directory, i.e. build/bench-data) must hold medium-ifod1.tck (made by
// `shared/data/make-tractograms.sh -o build/bench-data medium`); it is
// compressed once to medium-ifod1.fft there (again when the .tck is newer:
// delete the .fft after changing the encoder). Without it the benchmarks use
// shared/data/small-ifod1.tck and say so in their labels. Everything runs on
// one thread; times are compared as CPU time.
// scripts/bench_select.sh runs everything and prints the table of docs/select.md.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "fiblet/block_index.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/select.hpp"

namespace fs = std::filesystem;
using namespace fiblet;

namespace {

fs::path executable_dir() {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    return ec ? fs::current_path() : exe.parent_path();
}

// The benchmark file (compressed on first use) and its name for labels.
struct BenchFile {
    std::string path, label;
    std::unique_ptr<FftFile> file;
    std::unique_ptr<BlockIndex> index;
};

BenchFile& bench_file() {
    static BenchFile f = [] {
        BenchFile b;
        const char* env = std::getenv("FIBLET_BENCH_DATA");
        const fs::path dir = env ? fs::path(env) : executable_dir().parent_path() / "bench-data";
        fs::path tck = dir / "medium-ifod1.tck";
        b.label = "medium";
        if (!fs::exists(tck)) {
            tck = fs::path(FIBLET_SHARED_DIR) / "data" / "small-ifod1.tck";
            b.label = "small (medium-ifod1.tck not found)";
        }
        fs::create_directories(dir);
        const fs::path fft = dir / (tck.stem().string() + ".fft");
        if (!fs::exists(fft) || fs::last_write_time(fft) < fs::last_write_time(tck)) {
            CompressOptions o;
            o.overwrite = true;
            compress_file(tck.string(), fft.string(), o);
        }
        b.path = fft.string();
        b.file = std::make_unique<FftFile>(b.path);
        b.index = std::make_unique<BlockIndex>(BlockIndex::load(*b.file));
        return b;
    }();
    return f;
}

std::uint64_t kept_blocks(const Query& q) {
    SelectionStats s;
    select_runs(*bench_file().file, *bench_file().index, q, &s);
    return s.blocks;
}

// The query of a family keeping about `percent` % of the blocks: a
// parameter found by bisection (cached).
enum class Family { region_blocks, region_fibers, mask, frustum, frustum_lod, random_fibers };

// A mask image on a 2 mm grid over the scene: the voxels whose centre lies
// within `radius` of the origin (a region as a user's ROI image is one).
std::shared_ptr<const ImageMask> sphere_mask(float radius) {
    constexpr double kVoxelMm = 2;
    const auto n = std::int64_t(std::ceil(2 * (radius + kVoxelMm) / kVoxelMm)) + 1;
    MaskImage m;
    m.geometry.path = "sphere-mask";
    m.geometry.dims = {n, n, n};
    m.geometry.spacing = {kVoxelMm, kVoxelMm, kVoxelMm};
    const double origin = -kVoxelMm * double(n - 1) / 2;
    m.geometry.voxel_to_world = {{{kVoxelMm, 0, 0, origin}, {0, kVoxelMm, 0, origin}, {0, 0, kVoxelMm, origin}}};
    m.counts.assign(std::size_t(n * n * n), 0);
    for (std::int64_t k = 0; k < n; ++k)
        for (std::int64_t j = 0; j < n; ++j)
            for (std::int64_t i = 0; i < n; ++i) {
                const double x = origin + kVoxelMm * double(i), y = origin + kVoxelMm * double(j),
                             z = origin + kVoxelMm * double(k);
                m.counts[m.geometry.offset(i, j, k)] = x * x + y * y + z * z <= double(radius) * radius;
            }
    if (std::find(m.counts.begin(), m.counts.end(), 1) == m.counts.end())
        m.counts[m.geometry.offset(n / 2, n / 2, n / 2)] = 1;  // at least the centre voxel
    return std::make_shared<const ImageMask>(m);
}

Query make_query(Family family, double t) {
    Query q;
    const Vec3f centre{0, 0, 0};
    switch (family) {
        case Family::region_blocks:
            q.roi_mode = RoiMode::blocks;
            q.include.push_back(Region::sphere(centre, float(t)));
            break;
        case Family::region_fibers:
            q.include.push_back(Region::sphere(centre, float(t)));
            break;
        case Family::mask:
            q.include.push_back(Region::image(sphere_mask(float(t))));
            break;
        case Family::frustum:
        case Family::frustum_lod: {
            // A camera 250 mm away, zooming in: field of view t degrees and
            // a depth slab of +-2t mm around the centre.
            ViewSelection v;
            v.camera.position = {0, -30, 250};
            v.camera.target = centre;
            const float d = std::sqrt(30.0f * 30.0f + 250.0f * 250.0f);
            v.camera.fov_y_deg = float(t) + 0.01f;
            v.camera.near_mm = d - 2 * float(t);
            v.camera.far_mm = d + 2 * float(t) + 0.01f;
            v.camera.aspect = 1.0f;
            if (family == Family::frustum_lod) v.lod = Viewport{1024, 1024};
            q.view = v;
            break;
        }
        case Family::random_fibers:
            q.random_fraction = t;
            q.random_seed = 1;
            break;
    }
    return q;
}

Query query_keeping(Family family, int percent) {
    static std::map<std::pair<int, int>, Query> cache;
    const auto key = std::make_pair(int(family), percent);
    if (auto it = cache.find(key); it != cache.end()) return it->second;
    const double target = percent / 100.0 * double(bench_file().file->header().blocks);
    double lo = 0, hi = family == Family::random_fibers ? 1.0 : (family == Family::frustum || family == Family::frustum_lod ? 60.0 : 80.0);
    for (int i = 0; i < 22; ++i) {
        const double mid = 0.5 * (lo + hi);
        (double(kept_blocks(make_query(family, mid))) < target ? lo : hi) = mid;
    }
    return cache[key] = make_query(family, 0.5 * (lo + hi));
}

void report(benchmark::State& state, const SelectionStats& s) {
    const double blocks = double(bench_file().file->header().blocks);
    state.counters["kept_pct"] = 100.0 * double(s.blocks) / blocks;
    state.counters["read_pct"] = 100.0 * double(s.blocks_read) / blocks;
    state.counters["decoded_pct"] = 100.0 * double(s.blocks_decoded) / blocks;
    state.counters["tested_pct"] = 100.0 * double(s.blocks_tested) / blocks;
    state.counters["coarse_pct"] = 100.0 * double(s.coarse_blocks) / blocks;
    state.SetLabel(bench_file().label);
}

// Full decode with decode_file on one thread (as the selection runs), in
// chunks of state.range(0) blocks (0: the default, 4096 per thread, whose
// output stays in cache; 65536, the former default, is 47 MB of points per
// chunk).
void BM_SelectFullDecode(benchmark::State& state) {
    const FftFile& file = *bench_file().file;
    std::uint64_t points = 0;
    DecodeOptions o;
    o.chunk_blocks = std::size_t(state.range(0));
    o.threads = 1;
    for (auto _ : state) {
        decode_file(file, [&](std::uint64_t, const Streamlines& c) { points += c.point_count(); }, o);
        benchmark::DoNotOptimize(points);
    }
    state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(file.header().points));
    state.SetLabel(bench_file().label + ", " + decoder_name(resolve_decoder({})));
}
BENCHMARK(BM_SelectFullDecode)->Arg(0)->Arg(65536)->Unit(benchmark::kMillisecond);

void select_query(benchmark::State& state, Family family, const SelectOptions& options) {
    const Query q = query_keeping(family, int(state.range(0)));
    SelectionStats stats;
    for (auto _ : state) {
        std::uint64_t points = 0;
        stats = select(
            *bench_file().file, *bench_file().index, q, [&](const SelectedChunk& c) { points += c.point_count(); },
            options);
        benchmark::DoNotOptimize(points);
    }
    report(state, stats);
}

// The default: the candidate blocks copied out of the file's mapping.
void BM_SelectQuery(benchmark::State& state, Family family) { select_query(state, family, {}); }

// The same read with pread, spans with small gaps merged
// (SelectOptions::map_file off): what the mapping saves (docs/select.md).
void BM_SelectQueryPread(benchmark::State& state, Family family) {
    SelectOptions o;
    o.map_file = false;
    select_query(state, family, o);
}
BENCHMARK_CAPTURE(BM_SelectQueryPread, RegionBlocks, Family::region_blocks)->Arg(1)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SelectQueryPread, RegionFibers, Family::region_fibers)->Arg(1)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SelectQueryPread, Mask, Family::mask)->Arg(1)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SelectQueryPread, Frustum, Family::frustum)->Arg(1)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SelectQueryPread, RandomFibers, Family::random_fibers)->Arg(1)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SelectQuery, RegionBlocks, Family::region_blocks)->Arg(1)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SelectQuery, RegionFibers, Family::region_fibers)->Arg(1)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SelectQuery, Mask, Family::mask)->Arg(1)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SelectQuery, Frustum, Family::frustum)->Arg(1)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SelectQuery, FrustumLod, Family::frustum_lod)->Arg(1)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SelectQuery, RandomFibers, Family::random_fibers)->Arg(1)->Arg(10)->Arg(50)->Unit(benchmark::kMillisecond);

// The floor of a query: decode_blocks over exactly the blocks it keeps,
// copied together beforehand (nothing read, tested or walked), in calls of
// 4096 blocks into one buffer, as the full decode. Beside BM_SelectQuery in
// the same run, the difference is what selecting costs beyond decoding.
void BM_SelectKeptDecode(benchmark::State& state, Family family) {
    const FftFile& file = *bench_file().file;
    const std::size_t bb = file.header().block_bytes();
    std::vector<std::uint8_t> kept;
    std::uint64_t blocks = 0;
    for (const SelectedRun& r : select_runs(file, *bench_file().index, query_keeping(family, int(state.range(0))))) {
        kept.resize((blocks + r.block_count) * bb);
        file.read_blocks(r.first_block, r.block_count, kept.data() + blocks * bb);
        blocks += r.block_count;
    }
    constexpr std::size_t kChunk = 4096;
    std::vector<float> xyz(3 * kChunk * file.header().points_per_block);
    const DecodeContext ctx(file);
    for (auto _ : state) {
        std::size_t points = 0;
        for (std::uint64_t b = 0; b < blocks; b += kChunk)
            points += decode_blocks(ctx, kept.data() + b * bb, std::min<std::uint64_t>(kChunk, blocks - b), xyz.data());
        benchmark::DoNotOptimize(points);
    }
    state.counters["kept_pct"] = 100.0 * double(blocks) / double(file.header().blocks);
    state.SetLabel(bench_file().label);
}
BENCHMARK_CAPTURE(BM_SelectKeptDecode, RegionBlocks, Family::region_blocks)->Arg(1)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SelectKeptDecode, RegionFibers, Family::region_fibers)->Arg(1)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SelectKeptDecode, Mask, Family::mask)->Arg(1)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SelectKeptDecode, Frustum, Family::frustum)->Arg(1)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SelectKeptDecode, RandomFibers, Family::random_fibers)->Arg(1)->Arg(10)->Unit(benchmark::kMillisecond);

// select() with an empty query, in chunks of state.range(0) points (0:
// the default, 2^15; 262144, the former default, cycles the decoder's
// output through several MB).
void BM_SelectEverything(benchmark::State& state) {
    SelectOptions o;
    if (state.range(0)) o.chunk_points = std::size_t(state.range(0));
    SelectionStats stats;
    for (auto _ : state) {
        std::uint64_t points = 0;
        stats = select(
            *bench_file().file, *bench_file().index, Query{},
            [&](const SelectedChunk& c) { points += c.point_count(); }, o);
        benchmark::DoNotOptimize(points);
    }
    report(state, stats);
}
BENCHMARK(BM_SelectEverything)->Arg(0)->Arg(262144)->Unit(benchmark::kMillisecond);

void BM_SelectIndexLoad(benchmark::State& state) {
    const FftFile& file = *bench_file().file;
    for (auto _ : state) benchmark::DoNotOptimize(BlockIndex::load(file).blocks());
    const TrailerChunk* c = file.find_chunk(kBlockIndexTag);
    const double index_bytes = c ? double(c->payload.size() + 16) : 0.0;
    state.counters["index_bytes"] = index_bytes;
    state.counters["index_pct_of_file"] = 100.0 * index_bytes / double(file.file_size() - std::uint64_t(index_bytes));
    state.counters["bytes_per_block"] = index_bytes / double(file.header().blocks);
    state.SetLabel(bench_file().label);
}
BENCHMARK(BM_SelectIndexLoad)->Unit(benchmark::kMillisecond);

void BM_SelectIndexCompute(benchmark::State& state) {
    for (auto _ : state) benchmark::DoNotOptimize(BlockIndex::compute(*bench_file().file).blocks());
    state.SetLabel(bench_file().label);
}
BENCHMARK(BM_SelectIndexCompute)->Unit(benchmark::kMillisecond);

}  // namespace
