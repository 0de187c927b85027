// fiblet — reading .fft files.
//
// FftFile reads and validates the header and the fiber LUT up front (every
// count is checked against the file size before it is trusted), then reads
// blocks on demand, so a file of any size is opened in O(fibers) memory.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "fiblet/fft_format.hpp"

namespace fiblet {

namespace detail {
class FftzReader;
}

// Parses and validates a header from the first bytes of a file. `file_size`
// is the whole file's size (for the size checks); `name` is used in errors.
// Throws Error{fft_format}.
FftHeader parse_fft_header(std::span<const std::uint8_t> bytes, std::uint64_t file_size, const std::string& name);

// Opens plain .fft files and .fftz containers (formats/fftz.md) alike: a
// container is read through its seek table, decompressing only the frames
// that hold the requested bytes.
class FftFile {
public:
    explicit FftFile(const std::string& path);
    ~FftFile();
    FftFile(FftFile&&) noexcept;
    FftFile& operator=(FftFile&&) noexcept;
    FftFile(const FftFile&) = delete;
    FftFile& operator=(const FftFile&) = delete;

    const std::string& path() const { return path_; }
    const FftHeader& header() const { return header_; }
    // Bytes on disk; for a .fftz, logical_size() is that of the .fft it holds.
    std::uint64_t file_size() const { return file_size_; }
    std::uint64_t logical_size() const { return logical_size_; }
    bool is_zstd_container() const { return fftz_ != nullptr; }
    const std::vector<FiberLutEntry>& lut() const { return lut_; }

    // Global index of a fiber's first block, and its block count. The LUT is
    // validated at open: fibers' blocks are contiguous and in fiber order.
    std::uint64_t first_block(std::uint64_t fiber) const { return fiber_first_block_[fiber]; }
    std::uint32_t block_count(std::uint64_t fiber) const { return lut_[fiber].block_count(); }
    // Fibers whose blocks lie in [first_block(begin), first_block(end)).
    std::uint64_t block_end(std::uint64_t fiber_end) const {
        return fiber_end < header_.fibers ? fiber_first_block_[fiber_end] : header_.blocks;
    }

    // Chunks of the fiblet trailer (empty for files without one), and the
    // source .tck properties stored in its PROP chunk.
    const std::vector<TrailerChunk>& trailer() const { return trailer_; }
    const TrailerChunk* find_chunk(std::array<char, 4> tag) const;
    std::vector<std::pair<std::string, std::string>> properties() const;

    // Reads blocks [first, first+count) into `out` (count * block_bytes bytes).
    void read_blocks(std::uint64_t first, std::uint64_t count, std::uint8_t* out) const;
    std::vector<std::uint8_t> read_blocks(std::uint64_t first, std::uint64_t count) const;

private:
    void read_trailer();
    void read_at(std::uint8_t* out, std::uint64_t size, std::uint64_t offset) const;
    std::string path_;
    int fd_ = -1;
    std::uint64_t file_size_ = 0, logical_size_ = 0;
    std::unique_ptr<detail::FftzReader> fftz_;
    FftHeader header_;
    std::vector<FiberLutEntry> lut_;
    std::vector<std::uint64_t> fiber_first_block_;
    std::vector<TrailerChunk> trailer_;
};

}  // namespace fiblet
