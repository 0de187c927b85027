// fiblet — reading .fft files.
//
// FftFile reads and validates the header and the fiber LUT up front (every
// count is checked against the file size before it is trusted), then reads
// blocks on demand, so a file of any size is opened in O(fibers) memory
// (12 bytes per fiber). Every block read is checked against the LUT (point
// count, first/last flags) and, when the file carries a CSUM chunk
// (fiblet/checksum.hpp), against its checksums.
//
// A file with any byte after its last block is fiblet-written: its trailer
// must then be complete, end with a CSUM chunk, and match it, or the file
// does not open (Error{checksum}); FftOpenOptions::ignore_trailer is the
// explicit escape that salvages the blocks of such a file.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "fiblet/checksum.hpp"
#include "fiblet/fiber_ends.hpp"
#include "fiblet/streamline_field.hpp"
#include "fiblet/fft_format.hpp"
#include "fiblet/resample.hpp"

namespace fiblet {

namespace detail {
class FftzReader;
class InputRegistration;
}

// Parses and validates a header from the first bytes of a file. `file_size`
// is the whole file's size (for the size checks); `name` is used in errors.
// Throws Error{fft_format}.
FftHeader parse_fft_header(std::span<const std::uint8_t> bytes, std::uint64_t file_size, const std::string& name);

struct FftOpenOptions {
    // Check the CSUM chunk's hashes (header and LUT at open, block groups on
    // read) when the file has one. Off only where speed matters more than
    // detecting corruption (or to look at a damaged file).
    bool verify_checksums = true;
    // Read nothing after the last block: no checksums, properties, index or
    // resampling step. Salvages the blocks of a file whose trailer is damaged
    // (a reader that opens a file this way must say so to its user).
    bool ignore_trailer = false;
};

// Opens plain .fft files and .fftz containers (formats/fftz.md) alike: a
// container is read through its seek table, decompressing only the frames
// that hold the requested bytes.
class FftFile {
public:
    // Throws Error{io | fft_format | checksum | unsupported}.
    explicit FftFile(const std::string& path, FftOpenOptions options = {});
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

    // Chunks of the fiblet trailer (empty for files without one, or opened
    // with ignore_trailer), each validated at open (formats/fft.md §6).
    // Unknown chunks above 16 MiB are not loaded (memory stays bounded).
    bool has_trailer() const { return !trailer_.empty(); }
    const std::vector<TrailerChunk>& trailer() const { return trailer_; }
    const TrailerChunk* find_chunk(std::array<char, 4> tag) const;
    // The source .tck properties (PROP chunk), and how variable-step input
    // was resampled (RSMP chunk; empty when it was not resampled).
    const std::vector<std::pair<std::string, std::string>>& properties() const { return properties_; }
    const std::optional<Resampling>& resampling() const { return resampling_; }
    std::optional<double> resampled_step_mm() const {
        return resampling_ ? std::optional<double>(resampling_->step_mm) : std::nullopt;
    }
    // Bytes after the last block that were not read (ignore_trailer).
    std::uint64_t ignored_trailing_bytes() const {
        return options_.ignore_trailer ? logical_size_ - header_.file_bytes() : 0;
    }
    // The parsed CSUM chunk, or nullptr for a file without checksums.
    const FftChecksums* checksums() const { return checksums_ ? &*checksums_ : nullptr; }
    bool verifies_checksums() const { return checksums_ && options_.verify_checksums; }
    // The per-fiber last-step fractions of the ENDS chunk (fiblet/fiber_ends.hpp),
    // validated at open; null for a file without one (every fiber whole).
    const std::shared_ptr<const FiberEndFractions>& end_fractions() const { return end_fractions_; }
    // Per-streamline, per-point and group arrays of the source (DATA chunk,
    // formats/fft-data.md), validated at open; empty when it had none.
    const std::vector<StreamlineField>& streamline_fields() const;

    // Reads blocks [first, first+count) into `out` (count * block_bytes
    // bytes), checks them against the LUT (Error{fft_format}) and the
    // checksums of the groups they touch (Error{checksum}; the rest of a
    // group partly inside the range is read to hash it). Each group is
    // verified the first time any of its blocks is read. Thread-safe.
    void read_blocks(std::uint64_t first, std::uint64_t count, std::uint8_t* out) const;
    std::vector<std::uint8_t> read_blocks(std::uint64_t first, std::uint64_t count) const;

    // Blocks [first, first+count) of each span (ascending, not overlapping)
    // into `out`, one span after the other, checked as read_blocks checks
    // them, copied out of a read-only memory mapping of the file (made on
    // the first call, kept until the FftFile goes): no system call per span
    // and no bytes between spans. A file that shrinks meanwhile is
    // Error{fft_format} ("unexpected end of file") as with read_blocks: the
    // mapping is only read by a copy that catches the fault (SIGBUS).
    // False, with nothing read, when the file cannot be mapped (a .fftz
    // container, packed 16-bit blocks, mmap refused): use read_blocks then.
    struct BlockSpan {
        std::uint64_t first, count;
    };
    bool read_blocks_mapped(std::span<const BlockSpan> spans, std::uint8_t* out) const;

private:
    struct Mapping;
    void read_lut(std::uint64_t& lut_hash);
    void read_packed_lut_entry(std::uint64_t fiber, std::uint64_t buffer_base, std::uint64_t next_block);
    std::uint64_t fiber_of_block(std::uint64_t block) const;
    // Where block `block` (up to blocks) starts, in bytes after the first block, as stored.
    std::uint64_t stored_offset(std::uint64_t block) const;
    void expand_packed_blocks(std::uint64_t first, std::uint64_t count, const std::uint8_t* packed,
                              std::uint8_t* out) const;
    void open_trailer(std::span<const std::uint8_t> head, std::uint64_t lut_hash);
    void verify_open_checksums(std::span<const std::uint8_t> head, std::uint64_t lut_hash) const;
    // `fiber`: the fiber holding block `first` (fiber_of_block).
    void check_block_structure(std::uint64_t first, std::uint64_t count, const std::uint8_t* blocks,
                               std::uint64_t fiber) const;
    const std::uint8_t* mapped_first_block() const;
    void require_block_range(std::uint64_t first, std::uint64_t count) const;  // or Error{invalid_argument}
    [[noreturn]] void shrank_while_read() const;  // a mapped read faulted
    void require_size(std::uint64_t end) const;   // or shrank_while_read()
    void verify_block_groups(std::uint64_t first, std::uint64_t count, const std::uint8_t* blocks) const;
    bool groups_verified(std::uint64_t g0, std::uint64_t g1) const;  // checksum groups [g0, g1)
    void close() noexcept;

    void read_at(std::uint8_t* out, std::uint64_t size, std::uint64_t offset) const;
    std::string path_;
    FftOpenOptions options_;
    int fd_ = -1;
    std::uint64_t file_size_ = 0, logical_size_ = 0;
    std::unique_ptr<detail::FftzReader> fftz_;
    FftHeader header_;
    std::vector<FiberLutEntry> lut_;
    std::vector<std::uint32_t> fiber_first_block_;  // block counts are 32-bit, so are first blocks
    // Version 17 (packed blocks): each fiber's points and where its blocks
    // start (bytes after the first block); sums over the LUT as it is read.
    std::vector<std::uint32_t> fiber_points_;
    std::vector<std::uint64_t> fiber_offset_;
    std::uint64_t packed_points_ = 0, packed_bytes_ = 0;
    std::vector<TrailerChunk> trailer_;
    std::vector<std::pair<std::string, std::string>> properties_;
    std::optional<Resampling> resampling_;
    std::uint64_t trailer_hash_ = 0;  // XXH64 of the trailer chunks before CSUM, as read
    std::optional<FftChecksums> checksums_;
    std::shared_ptr<const FiberEndFractions> end_fractions_;
    std::shared_ptr<const std::vector<StreamlineField>> fields_;
    std::unique_ptr<std::atomic<std::uint64_t>[]> verified_groups_;  // one bit per block group
    std::unique_ptr<Mapping> mapping_;                                // read_blocks_mapped()
    std::unique_ptr<detail::InputRegistration> input_;  // no output of this process may replace the file
};

}  // namespace fiblet
