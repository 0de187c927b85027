#include "select/block_batch_reader.hpp"

#include <algorithm>

namespace fiblet::detail {

BlockBatchReader::BlockBatchReader(const FftFile& file, bool use_mapping, std::uint64_t max_gap_blocks)
    : file_(file), use_mapping_(use_mapping), max_gap_(max_gap_blocks), block_bytes_(file.header().block_bytes()) {}

void BlockBatchReader::read(const std::vector<std::uint32_t>& blocks) {
    pointers_.resize(blocks.size());
    if (blocks.empty()) return;
    // Spans [first, last] of blocks: runs of consecutive blocks when mapped
    // (gap blocks would only be checked for nothing), runs with gaps up to
    // max_gap_ between them when read.
    const std::uint64_t gap = use_mapping_ ? 0 : max_gap_;
    struct Span {
        std::uint64_t first, last;
        std::size_t first_item;
    };
    std::vector<Span> spans{{blocks[0], blocks[0], 0}};
    for (std::size_t i = 1; i < blocks.size(); ++i) {
        Span& s = spans.back();
        if (blocks[i] - s.last <= gap + 1)
            s.last = blocks[i];
        else
            spans.push_back({blocks[i], blocks[i], i});
    }
    auto point = [&](std::size_t s, const std::uint8_t* at) {
        const std::size_t end = s + 1 < spans.size() ? spans[s + 1].first_item : blocks.size();
        for (std::size_t i = spans[s].first_item; i < end; ++i)
            pointers_[i] = at + (blocks[i] - spans[s].first) * block_bytes_;
        blocks_read_ += spans[s].last - spans[s].first + 1;
    };
    if (use_mapping_) {
        // Scattered blocks miss the cache: fetch the spans a few ahead.
        const std::uint8_t* base = nullptr;
        for (std::size_t s = 0; s < spans.size(); ++s) {
            if (base && s + 8 < spans.size()) {
                const std::uint8_t* ahead = base + (spans[s + 8].first - spans[0].first) * block_bytes_;
                __builtin_prefetch(ahead), __builtin_prefetch(ahead + 64);
            }
            const auto m = file_.mapped_blocks(spans[s].first, spans[s].last - spans[s].first + 1);
            if (s == 0 && !m.empty()) {
                base = m.data();
                for (std::size_t a = 1; a < std::min<std::size_t>(8, spans.size()); ++a) {
                    const std::uint8_t* ahead = base + (spans[a].first - spans[0].first) * block_bytes_;
                    __builtin_prefetch(ahead), __builtin_prefetch(ahead + 64);
                }
            }
            if (m.empty()) {  // the file cannot be mapped (that fails on the first call or never)
                use_mapping_ = false;
                return read(blocks);
            }
            point(s, m.data());
        }
        return;
    }
    std::uint64_t total = 0;
    for (const Span& s : spans) total += s.last - s.first + 1;
    buffer_.resize(total * block_bytes_);
    std::uint8_t* at = buffer_.data();
    for (std::size_t s = 0; s < spans.size(); ++s) {
        const std::uint64_t n = spans[s].last - spans[s].first + 1;
        file_.read_blocks(spans[s].first, n, at);
        point(s, at);
        at += n * block_bytes_;
    }
}

}  // namespace fiblet::detail
