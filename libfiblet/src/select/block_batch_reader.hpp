// Internal: reads a sorted set of scattered blocks with few system calls:
// blocks closer than a small gap are read in one span (the gap bytes cost
// less than another read).
#pragma once

#include <cstdint>
#include <vector>

#include "fiblet/fft_file.hpp"

namespace fiblet::detail {

class BlockBatchReader {
public:
    explicit BlockBatchReader(const FftFile& file, std::uint64_t max_gap_blocks = 8);

    // Reads `blocks` (ascending, unique); block(i) then points at blocks[i].
    void read(const std::vector<std::uint32_t>& blocks);
    const std::uint8_t* block(std::size_t i) const { return pointers_[i]; }
    // Blocks transferred so far, gaps included.
    std::uint64_t blocks_read() const { return blocks_read_; }

private:
    const FftFile& file_;
    std::uint64_t max_gap_;
    std::uint32_t block_bytes_;
    std::vector<std::uint8_t> buffer_;
    std::vector<const std::uint8_t*> pointers_;
    std::uint64_t blocks_read_ = 0;
};

}  // namespace fiblet::detail
