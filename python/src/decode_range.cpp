#include "decode_range.hpp"

#include <cstdlib>
#include <string_view>
#include <exception>
#include <string>

#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"

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

// Room for `blocks` full blocks, pages untouched until written.
DecodedRange with_room_for(const FftFile& file, std::uint64_t blocks, std::uint64_t fibers) {
    DecodedRange out;
    out.xyz = PopulatedBuffer(blocks * file.header().points_per_block * 3 * sizeof(float), output_page_mode());
    out.offsets.resize(fibers + 1);
    return out;
}

}  // namespace

// The library's parallel decode (decode_fibers_into) into room for every
// block full; the rest given back after.
DecodedRange decode_range(const FftFile& file, std::uint64_t begin, std::uint64_t end, unsigned threads) {
    if (begin > end || end > file.header().fibers)
        throw Error(Errc::invalid_argument, file.path() + ": fiber range past the end");
    DecodedRange out = with_room_for(file, file.block_end(end) - file.block_end(begin), end - begin);
    DecodeOptions options;
    options.threads = threads;
    out.points = decode_fibers_into(file, begin, end, {out.xyz.as<float>(), out.xyz.bytes() / sizeof(float)}, out.offsets,
                                    options);
    out.xyz.shrink(out.points * 3 * sizeof(float));
    return out;
}

DecodedRange decode_kept(const FftFile& file, const FiberRegionTest& test, std::span<const FiberRange> candidates,
                         unsigned threads, std::vector<std::uint64_t>& fibers) {
    std::uint64_t blocks = 0;
    for (const FiberRange& r : candidates) blocks += file.block_end(r.last + 1) - file.first_block(r.first);
    DecodedRange out = with_room_for(file, blocks, 0);
    out.points = test.decode_kept_into(candidates, {out.xyz.as<float>(), out.xyz.bytes() / sizeof(float)}, out.offsets,
                                       fibers, threads);
    out.xyz.shrink(out.points * 3 * sizeof(float));
    return out;
}

}  // namespace fiblet::python
