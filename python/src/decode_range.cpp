#include "decode_range.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <exception>
#include <string>
#include <thread>

#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/parallel.hpp"

namespace fiblet::python {
namespace {

// The output's pages: FIBLET_PY_BUFFER=populate|huge picks one for
// measuring (scripts/bench_python.sh); the default is the faster on the
// medium tractogram (bench/results.md).
PageMode output_page_mode() {
    const char* v = std::getenv("FIBLET_PY_BUFFER");
    if (v && std::string_view(v) == "populate") return PageMode::populate;
    return PageMode::huge;
}

}  // namespace

DecodedRange decode_range(const FftFile& file, std::uint64_t begin, std::uint64_t end, unsigned threads) {
    if (begin > end || end > file.header().fibers)
        throw Error(Errc::invalid_argument, file.path() + ": fiber range past the end");
    // Blocks in their in-memory layout (read_blocks expands version 17's
    // packed ones), 8- or 16-bit alike.
    const DecodeContext ctx(file);
    const std::uint32_t bb = ctx.header.block_bytes();
    const std::uint64_t b0 = file.block_end(begin), nblocks = file.block_end(end) - b0;
    PopulatedBuffer blocks(nblocks * bb, PageMode::huge);
    std::uint8_t* data = blocks.as<std::uint8_t>();

    // Contiguous runs of blocks, up to 4 per thread, handed out one at a time
    // by the library's pool (fiblet/parallel.hpp): each run is read and
    // counted, then decoded at its own point offset, all in parallel.
    if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
    const std::uint64_t runs =
        threads == 1 ? 1 : std::clamp<std::uint64_t>(nblocks / 1024, 1, std::uint64_t(4) * threads);
    std::vector<std::uint64_t> run_block(runs + 1), run_point(runs + 1, 0);
    for (std::uint64_t r = 0; r <= runs; ++r) run_block[r] = nblocks * r / runs;
    parallel_for(runs, threads, [&](std::size_t r) {
        const std::uint64_t n = run_block[r + 1] - run_block[r];
        file.read_blocks(b0 + run_block[r], n, data + run_block[r] * bb);
        run_point[r + 1] = count_block_points(ctx, data + run_block[r] * bb, n);
    });
    for (std::uint64_t r = 0; r < runs; ++r) run_point[r + 1] += run_point[r];

    DecodedRange out;
    out.points = run_point[runs];
    out.xyz = PopulatedBuffer(out.points * 3 * sizeof(float), output_page_mode());
    float* xyz = out.xyz.as<float>();
    parallel_for(runs, threads, [&](std::size_t r) {
        decode_blocks(ctx, data + run_block[r] * bb, run_block[r + 1] - run_block[r], xyz + 3 * run_point[r], {}, 1u);
    });

    // Per-fiber offsets from the blocks' point counts.
    out.offsets.reserve(end - begin + 1);
    std::uint64_t b = 0, acc = 0;
    for (std::uint64_t f = begin; f < end; ++f) {
        for (std::uint32_t k = 0; k < file.block_count(f); ++k, ++b) acc += block_flags(ctx.header, data + b * bb).point_count;
        out.offsets.push_back(acc);
    }
    return out;
}

void keep_fibers(DecodedRange& range, const std::vector<std::uint64_t>& keep) {
    float* xyz = range.xyz.as<float>();
    std::vector<std::uint64_t> offsets{0};
    offsets.reserve(keep.size() + 1);
    for (const std::uint64_t f : keep) {
        const std::uint64_t first = range.offsets[f], n = range.offsets[f + 1] - first;
        if (n) std::memmove(xyz + 3 * offsets.back(), xyz + 3 * first, 12 * n);  // ascending: never ahead of its source
        offsets.push_back(offsets.back() + n);
    }
    range.offsets = std::move(offsets);
    range.points = range.offsets.back();
    range.xyz.shrink(12 * range.points);
}

}  // namespace fiblet::python
