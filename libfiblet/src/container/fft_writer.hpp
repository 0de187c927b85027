// Internal: the one writer of .fft files, for compress and for subsets
// (fft_subset.cpp): the fiber table's split into GPU buffers (formats/fft.md
// §3), the header and fiber table, the blocks with their checksums, then
// the trailer chunks with the CSUM chunk last and the header rewritten with
// its final fields. Through an FftSink: the plain file or the .fftz
// container (fft_sink.hpp).
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fiblet/checksum.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_format.hpp"
#include "container/packed_blocks16.hpp"
#include "container/fft_sink.hpp"

namespace fiblet::detail {

// A fiber's blocks and points, as the fiber table plans them.
struct FiberBlocks {
    std::uint32_t blocks = 0, points = 0;
};

// The fiber table (LUT) and the header's block count and buffer table for
// `fibers` fibers, fiber_at(i) giving fiber i's FiberBlocks (at most 65535
// blocks: the callers check): each fiber's blocks in one GPU buffer of at
// most fft_max_blocks_per_buffer blocks. Version 17 stores the fiber's point
// count where versions 2 and 16 store its first block in its buffer, and
// adds its packed blocks' bytes to h.packed_block_bytes.
template <class FiberAt>
std::vector<FiberLutEntry> plan_fiber_table(FftHeader& h, std::size_t fibers, FiberAt&& fiber_at, const std::string& path) {
    std::vector<FiberLutEntry> lut(fibers);
    const std::uint64_t per_buffer = fft_max_blocks_per_buffer(h.block_bytes());
    std::uint64_t blocks = 0, in_buffer = 0;
    h.buffer_ends.clear();
    h.packed_block_bytes = 0;
    for (std::size_t f = 0; f < fibers; ++f) {
        const FiberBlocks fb = fiber_at(f);
        if (in_buffer + fb.blocks > per_buffer) h.buffer_ends.push_back(blocks), in_buffer = 0;
        if (h.buffer_ends.size() > 254) throw Error(Errc::unsupported, path + ": more than 255 GPU buffers of blocks");
        lut[f] = {std::uint32_t(h.buffer_ends.size()) << 16 | fb.blocks, h.packed() ? fb.points : std::uint32_t(in_buffer)};
        if (h.packed() && fb.blocks > 0)
            h.packed_block_bytes += (fb.blocks - 1) * std::uint64_t{packed16_block_bytes(h.points_per_block)} +
                                    packed16_block_bytes(fb.points - (fb.blocks - 1) * h.points_per_block);
        blocks += fb.blocks, in_buffer += fb.blocks;
    }
    if (blocks > std::numeric_limits<std::uint32_t>::max()) throw Error(Errc::unsupported, path + ": more than 2^32 - 1 blocks");
    if (blocks > 0) h.buffer_ends.push_back(blocks);
    h.blocks = std::uint32_t(blocks);
    return lut;
}

class FftWriter {
public:
    // Opens the output (atomically: nothing is at `path` until commit) and
    // writes the header, a placeholder that finish rewrites, and the fiber
    // table. `zstd` set: the .fftz container, groups compressed by up to
    // `threads` threads.
    FftWriter(const std::string& path, bool overwrite, const std::optional<ZstdOptions>& zstd, const FftHeader& h,
              std::span<const FiberLutEntry> lut, unsigned threads = 1);

    // Whole blocks in file order, as stored: fixed-size blocks, or version
    // 17's packed blocks of these sizes; their checksums with them.
    void write_blocks(std::span<const std::uint8_t> blocks);
    void write_packed_blocks(std::span<const std::uint8_t> packed, std::span<const std::uint32_t> sizes);

    // The trailer: `chunks`, then the CSUM chunk that covers them and the
    // final header; then the header rewritten. Returns the bytes stored.
    std::uint64_t finish(const FftHeader& h, std::vector<TrailerChunk> chunks);
    void commit() { sink_->commit(); }

private:
    std::unique_ptr<FftSink> sink_;
    FftChecksumBuilder checksum_;
};

}  // namespace fiblet::detail
