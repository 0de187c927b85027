#include <algorithm>

#include "decode/decode_scalar16.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"

namespace fiblet {

namespace {

// Decodes fibers [begin, end) whose blocks are already in memory.
void decode_fiber_range(const FftFile& file, const DecodeContext& ctx, std::uint64_t begin, std::uint64_t end,
                        const std::vector<std::uint8_t>& blocks, Streamlines& out) {
    if (ctx.header.direction_bits() == 16) return detail::decode_fiber_range16(file, ctx, begin, end, blocks, out);
    const std::size_t nblocks = blocks.size() / ctx.header.block_bytes();
    const std::size_t npoints = count_block_points(ctx, blocks.data(), nblocks);
    out.xyz.resize(3 * npoints);
    decode_blocks_scalar(ctx, blocks.data(), nblocks, out.xyz.data());
    // Per-fiber offsets from the blocks' point counts.
    out.offsets.assign(1, 0);
    out.offsets.reserve(end - begin + 1);
    const std::uint32_t bb = ctx.header.block_bytes();
    std::size_t b = 0;
    std::uint64_t acc = 0;
    for (std::uint64_t f = begin; f < end; ++f) {
        for (std::uint32_t k = 0; k < file.block_count(f); ++k, ++b) acc += BlockView{&blocks[b * bb]}.point_count();
        out.offsets.push_back(acc);
    }
}

}  // namespace

Streamlines decode_fibers(const FftFile& file, std::uint64_t begin, std::uint64_t end, const DecodeOptions&) {
    if (begin > end || end > file.header().fibers)
        throw Error(Errc::invalid_argument, file.path() + ": fiber range past the end");
    const DecodeContext ctx(file.header());
    const std::uint64_t b0 = file.block_end(begin), b1 = file.block_end(end);
    Streamlines out;
    decode_fiber_range(file, ctx, begin, end, file.read_blocks(b0, b1 - b0), out);
    return out;
}

void decode_file(const FftFile& file, const std::function<void(std::uint64_t, const Streamlines&)>& sink,
                 const DecodeOptions& options) {
    const DecodeContext ctx(file.header());
    const std::uint64_t fibers = file.header().fibers;
    Streamlines chunk;
    std::vector<std::uint8_t> blocks;
    std::uint64_t f = 0;
    while (f < fibers) {
        // Whole fibers, at least one, up to chunk_blocks blocks.
        std::uint64_t e = f + 1;
        while (e < fibers && file.block_end(e + 1) - file.block_end(f) <= options.chunk_blocks) ++e;
        const std::uint64_t b0 = file.block_end(f), b1 = file.block_end(e);
        blocks.resize((b1 - b0) * ctx.header.block_bytes());
        file.read_blocks(b0, b1 - b0, blocks.data());
        decode_fiber_range(file, ctx, f, e, blocks, chunk);
        sink(f, chunk);
        f = e;
    }
}

}  // namespace fiblet
