#include "select/block_batch_reader.hpp"

#include <algorithm>

namespace fiblet::detail {

BlockBatchReader::BlockBatchReader(const FftFile& file, bool use_mapping, std::uint64_t max_gap_blocks)
    : file_(file), use_mapping_(use_mapping), max_gap_(max_gap_blocks), block_bytes_(file.header().block_bytes()) {}

void BlockBatchReader::read(const std::vector<std::uint32_t>& blocks) {
    pointers_.resize(blocks.size());
    if (blocks.empty()) return;
    // Spans of blocks: runs of consecutive blocks when copied out of the
    // mapping (only the blocks asked for), runs with gaps up to max_gap_
    // between them when read (the gap bytes cost less than another read).
    const std::uint64_t gap = use_mapping_ ? 0 : max_gap_;
    spans_.assign(1, {blocks[0], 1});
    for (std::size_t i = 1; i < blocks.size(); ++i) {
        FftFile::BlockSpan& s = spans_.back();
        if (blocks[i] - (s.first + s.count - 1) <= gap + 1)
            s.count = blocks[i] - s.first + 1;
        else
            spans_.push_back({blocks[i], 1});
    }
    std::uint64_t total = 0;
    for (const FftFile::BlockSpan& s : spans_) total += s.count;
    buffer_.resize(total * block_bytes_);
    if (use_mapping_ && !file_.read_blocks_mapped(spans_, buffer_.data())) {
        use_mapping_ = false;  // the file cannot be mapped (that fails on the first call or never)
        return read(blocks);
    }
    // Block i's place: its span's place in the buffer plus its offset in the span.
    std::uint8_t* at = buffer_.data();
    std::size_t i = 0;
    for (const FftFile::BlockSpan& s : spans_) {
        if (!use_mapping_) file_.read_blocks(s.first, s.count, at);
        for (; i < blocks.size() && blocks[i] < s.first + s.count; ++i) pointers_[i] = at + (blocks[i] - s.first) * block_bytes_;
        at += s.count * block_bytes_;
    }
    blocks_read_ += total;
}

}  // namespace fiblet::detail
