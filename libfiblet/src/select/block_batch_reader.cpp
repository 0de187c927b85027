#include "select/block_batch_reader.hpp"

namespace fiblet::detail {

BlockBatchReader::BlockBatchReader(const FftFile& file, bool use_mapping, std::uint64_t max_gap_blocks)
    : file_(file), max_gap_(max_gap_blocks), block_bytes_(file.header().block_bytes()) {
    if (use_mapping) mapped_ = file.mapped_blocks();
}

void BlockBatchReader::read(const std::vector<std::uint32_t>& blocks) {
    pointers_.resize(blocks.size());
    if (blocks.empty()) return;
    if (!mapped_.empty()) {
        for (std::size_t i = 0; i < blocks.size(); ++i)
            pointers_[i] = mapped_.data() + std::uint64_t(blocks[i]) * block_bytes_;
        blocks_read_ += blocks.size();
        return;
    }
    // Spans [first, last] of blocks with gaps up to max_gap_ between them.
    struct Span {
        std::uint64_t first, last;
        std::size_t first_item;
    };
    std::vector<Span> spans{{blocks[0], blocks[0], 0}};
    std::uint64_t total = 1;
    for (std::size_t i = 1; i < blocks.size(); ++i) {
        Span& s = spans.back();
        if (blocks[i] - s.last <= max_gap_ + 1) {
            total += blocks[i] - s.last;
            s.last = blocks[i];
        } else {
            spans.push_back({blocks[i], blocks[i], i});
            ++total;
        }
    }
    buffer_.resize(total * block_bytes_);
    std::uint8_t* at = buffer_.data();
    for (std::size_t s = 0; s < spans.size(); ++s) {
        const Span& span = spans[s];
        const std::uint64_t n = span.last - span.first + 1;
        file_.read_blocks(span.first, n, at);
        const std::size_t end = s + 1 < spans.size() ? spans[s + 1].first_item : blocks.size();
        for (std::size_t i = span.first_item; i < end; ++i) pointers_[i] = at + (blocks[i] - span.first) * block_bytes_;
        at += n * block_bytes_;
    }
    blocks_read_ += total;
}

}  // namespace fiblet::detail
