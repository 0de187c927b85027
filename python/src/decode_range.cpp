#include "decode_range.hpp"

#include <cstdlib>
#include <cstring>
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

}  // namespace

DecodedRange decode_range(const FftFile& file, std::uint64_t begin, std::uint64_t end, unsigned threads) {
    if (begin > end || end > file.header().fibers)
        throw Error(Errc::invalid_argument, file.path() + ": fiber range past the end");
    // The library's parallel decode (decode_fibers_into) into room for every
    // block full, pages untouched until written; the rest given back after.
    const std::uint64_t most = (file.block_end(end) - file.block_end(begin)) * file.header().points_per_block;
    DecodedRange out;
    out.xyz = PopulatedBuffer(most * 3 * sizeof(float), output_page_mode());
    out.offsets.resize(end - begin + 1);
    DecodeOptions options;
    options.threads = threads;
    out.points = decode_fibers_into(file, begin, end, {out.xyz.as<float>(), 3 * most}, out.offsets, options);
    out.xyz.shrink(out.points * 3 * sizeof(float));
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
