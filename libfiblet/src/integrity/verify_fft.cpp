// Whole-file verification: structure and every checksum of a .fft file.
#include <algorithm>
#include <vector>

#include "fiblet/checksum.hpp"
#include "fiblet/fft_file.hpp"

namespace fiblet {

VerifyReport verify_fft_file(const std::string& path, const std::function<void(double)>& progress) {
    const FftFile file(path, {.verify_checksums = true});  // header, LUT and trailer hashes checked here
    const FftHeader& h = file.header();
    VerifyReport r;
    r.has_checksum = file.checksums() != nullptr;
    r.blocks = h.blocks;
    if (!file.has_trailer()) r.unrecognized_trailing_bytes = file.logical_size() - h.file_bytes();
    // Whole checksum groups at a time, so that no block is read twice.
    const std::uint64_t group = r.has_checksum ? file.checksums()->group_blocks : kDefaultChecksumGroupBlocks;
    const std::uint64_t step = std::max<std::uint64_t>(1, (std::uint64_t{4} << 20) / h.block_bytes() / group) * group;
    std::vector<std::uint8_t> buf;
    for (std::uint64_t b = 0; b < h.blocks; b += step) {
        const std::uint64_t n = std::min<std::uint64_t>(step, h.blocks - b);
        buf.resize(n * h.block_bytes());
        file.read_blocks(b, n, buf.data());  // checks structure and the groups' hashes
        r.bytes_read += buf.size();
        if (progress) progress(double(b + n) / double(h.blocks));
    }
    if (r.has_checksum) r.groups = file.checksums()->group_count(h.blocks);
    r.bytes_read += h.blocks_offset();
    return r;
}

}  // namespace fiblet
