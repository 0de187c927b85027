// Internal: a sorted set of scattered blocks in memory, checked as
// FftFile::read_blocks checks them. Copied out of the file's memory mapping
// when it has one (just those blocks, no system call per block); else read
// in spans where blocks closer than a small gap share one read.
#pragma once

#include <cstdint>
#include <vector>

#include "core/default_init_allocator.hpp"
#include "fiblet/fft_file.hpp"

namespace fiblet::detail {

class BlockBatchReader {
public:
    BlockBatchReader(const FftFile& file, bool use_mapping, std::uint64_t max_gap_blocks = 64);

    // Reads `blocks` (ascending, unique); block(i) then points at blocks[i],
    // and consecutive blocks lie one after the other in memory.
    void read(const std::vector<std::uint32_t>& blocks);
    const std::uint8_t* block(std::size_t i) const { return pointers_[i]; }
    // Blocks copied (mapped) or read (gaps included) so far.
    std::uint64_t blocks_read() const { return blocks_read_; }

private:
    const FftFile& file_;
    bool use_mapping_;
    std::uint64_t max_gap_;
    std::uint32_t block_bytes_;
    std::vector<FftFile::BlockSpan> spans_;
    UninitializedVector<std::uint8_t> buffer_;  // written right after it grows
    std::vector<const std::uint8_t*> pointers_;
    std::uint64_t blocks_read_ = 0;
};

}  // namespace fiblet::detail
