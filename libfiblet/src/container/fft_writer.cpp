#include "container/fft_writer.hpp"

#include <utility>

namespace fiblet::detail {

FftWriter::FftWriter(const std::string& path, bool overwrite, const std::optional<ZstdOptions>& zstd, const FftHeader& h,
                     std::span<const FiberLutEntry> lut, unsigned threads)
    : sink_(open_fft_sink(path, overwrite, zstd, h.direction_bits(), h.block_bytes(), threads)),
      checksum_(h.block_bytes()) {
    const std::span<const std::uint8_t> lut_bytes{reinterpret_cast<const std::uint8_t*>(lut.data()), lut.size_bytes()};
    sink_->begin(serialize_fft_header(h), lut_bytes);
    checksum_.add_lut(lut_bytes.data(), lut_bytes.size());
}

void FftWriter::write_blocks(std::span<const std::uint8_t> blocks) {
    sink_->write_blocks(blocks);
    checksum_.add_blocks(blocks.data(), blocks.size());
}

void FftWriter::write_packed_blocks(std::span<const std::uint8_t> packed, std::span<const std::uint32_t> sizes) {
    sink_->write_blocks(packed);
    const std::uint8_t* p = packed.data();  // checksums cover the bytes as stored
    for (const std::uint32_t n : sizes) checksum_.add_block(p, n), p += n;
}

std::uint64_t FftWriter::finish(const FftHeader& h, std::vector<TrailerChunk> chunks) {
    const auto head = serialize_fft_header(h);
    const std::uint64_t at = sink_->logical_size();
    chunks.push_back(checksum_.finish(head, chunks));  // last: it covers the chunks before it
    sink_->finish(serialize_trailer(chunks, at), head);
    return sink_->stored_size();
}

}  // namespace fiblet::detail
