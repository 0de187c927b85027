// The CSUM trailer chunk: its payload, and building it while a file is written.
#include <algorithm>
#include <string>

#include "core/bytes.hpp"
#include "fiblet/checksum.hpp"
#include "fiblet/error.hpp"

namespace fiblet {
using detail::get_le;
using detail::put_le;

FftChecksums FftChecksums::parse(const TrailerChunk& chunk, std::uint64_t blocks, const std::string& name) {
    const auto& p = chunk.payload;
    auto bad = [&](const std::string& what) {
        throw Error(Errc::checksum, name + ": damaged CSUM chunk: " + what);
    };
    if (p.size() < kChecksumFixedBytes) bad("only " + std::to_string(p.size()) + " bytes");
    FftChecksums s;
    s.algorithm = get_le<std::uint32_t>(&p[0]);
    s.group_blocks = get_le<std::uint32_t>(&p[4]);
    if (s.algorithm != kChecksumXxh64)
        bad("unknown checksum algorithm " + std::to_string(s.algorithm) + " (fiblet knows 1 = XXH64)");
    if (s.group_blocks == 0) bad("zero blocks per group");
    s.header_hash = get_le<std::uint64_t>(&p[8]);
    s.lut_hash = get_le<std::uint64_t>(&p[16]);
    s.trailer_hash = get_le<std::uint64_t>(&p[24]);
    const std::uint64_t groups = s.group_count(blocks);
    if ((p.size() - kChecksumFixedBytes) / 8 != groups || (p.size() - kChecksumFixedBytes) % 8 != 0)
        bad(std::to_string(p.size()) + " bytes for " + std::to_string(groups) + " block groups");
    s.group_hashes.resize(groups);
    for (std::uint64_t g = 0; g < groups; ++g) s.group_hashes[g] = get_le<std::uint64_t>(&p[kChecksumFixedBytes + 8 * g]);
    return s;
}

TrailerChunk FftChecksums::serialize() const {
    TrailerChunk c{kChecksumTag, {}};
    c.payload.reserve(kChecksumFixedBytes + 8 * group_hashes.size());
    put_le(c.payload, algorithm);
    put_le(c.payload, group_blocks);
    put_le(c.payload, header_hash);
    put_le(c.payload, lut_hash);
    put_le(c.payload, trailer_hash);
    for (std::uint64_t h : group_hashes) put_le(c.payload, h);
    return c;
}

FftChecksumBuilder::FftChecksumBuilder(std::uint32_t block_bytes, std::uint32_t group_blocks)
    : block_bytes_(block_bytes) {
    if (group_blocks == 0) throw Error(Errc::invalid_argument, "checksum groups need at least one block");
    sums_.group_blocks = group_blocks;
}

void FftChecksumBuilder::add_lut(const void* data, std::size_t bytes) { lut_.update(data, bytes); }

void FftChecksumBuilder::add_blocks(const void* data, std::size_t bytes) {
    const std::uint64_t group_size = std::uint64_t{sums_.group_blocks} * block_bytes_;
    const auto* p = static_cast<const std::uint8_t*>(data);
    while (bytes > 0) {
        const std::size_t take = std::size_t(std::min<std::uint64_t>(bytes, group_size - group_bytes_));
        group_.update(p, take);
        p += take, bytes -= take, group_bytes_ += take;
        if (group_bytes_ == group_size) {
            sums_.group_hashes.push_back(group_.digest());
            group_.reset();
            group_bytes_ = 0;
        }
    }
}

void FftChecksumBuilder::add_block(const void* data, std::size_t bytes) {
    group_.update(data, bytes);
    if (++group_block_count_ == sums_.group_blocks) {
        sums_.group_hashes.push_back(group_.digest());
        group_.reset();
        group_block_count_ = 0;
    }
}

TrailerChunk FftChecksumBuilder::finish(std::span<const std::uint8_t> header,
                                        const std::vector<TrailerChunk>& chunks_before) {
    if (group_bytes_ > 0 || group_block_count_ > 0) {  // the last, shorter group
        sums_.group_hashes.push_back(group_.digest());
        group_.reset();
        group_bytes_ = 0, group_block_count_ = 0;
    }
    sums_.header_hash = xxh64(header.data(), header.size());
    sums_.lut_hash = lut_.digest();
    Xxh64Stream before;  // the chunks as serialized, hashed piece by piece: a DATA chunk may be large
    for (const TrailerChunk& c : chunks_before) {
        std::vector<std::uint8_t> head;
        append_trailer_chunk_head(head, c);
        before.update(head.data(), head.size());
        before.update(c.payload.data(), c.payload.size());
    }
    sums_.trailer_hash = before.digest();
    return sums_.serialize();
}

}  // namespace fiblet
