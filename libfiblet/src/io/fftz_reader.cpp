#include "io/fftz_reader.hpp"

#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "core/bytes.hpp"
#include "fiblet/error.hpp"

namespace fiblet::detail {

namespace {

constexpr std::size_t kFrameHeaderBytes = 8;  // skippable frame: magic, size
constexpr std::uint32_t kMaxFrameBytes = 1u << 30;

void pread_exact(int fd, std::uint8_t* out, std::uint64_t size, std::uint64_t offset, const std::string& name) {
    while (size > 0) {
        const ssize_t n = ::pread(fd, out, size, off_t(offset));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw Error(Errc::io, name + ": read failed: " + std::strerror(errno));
        if (n == 0) throw Error(Errc::fft_format, name + ": not a valid .fftz file: unexpected end of file");
        out += n, size -= std::uint64_t(n), offset += std::uint64_t(n);
    }
}

}  // namespace

bool FftzReader::recognizes(const std::uint8_t* p, std::size_t size) {
    return size >= 12 && get_le<std::uint32_t>(p) == kZstdSkippableMagic && std::memcmp(p + 8, kFftzMagic, 4) == 0;
}

FftzReader::FftzReader(int fd, std::uint64_t file_size, std::string name) : fd_(fd), name_(std::move(name)) {
    auto bad = [&](const std::string& what) {
        throw Error(Errc::fft_format, name_ + ": not a valid .fftz file: " + what);
    };
    // Seek table: footer (frame count, descriptor, magic), entries, skippable frame header.
    if (file_size < kFrameHeaderBytes + 9) bad("too short for a seek table");
    std::uint8_t footer[9];
    pread_exact(fd_, footer, 9, file_size - 9, name_);
    if (get_le<std::uint32_t>(footer + 5) != kZstdSeekableFooterMagic) bad("no zstd seek table at the end");
    const std::uint32_t count = get_le<std::uint32_t>(footer);
    const std::uint8_t table_descriptor = footer[4];
    if (table_descriptor & 0x7c) bad("reserved bits set in the seek table descriptor");
    const std::uint64_t entry_bytes = (table_descriptor & 0x80) ? 12 : 8;
    const std::uint64_t table_bytes = std::uint64_t(count) * entry_bytes + 9;
    if (table_bytes + kFrameHeaderBytes > file_size) bad("seek table larger than the file");
    const std::uint64_t table_at = file_size - table_bytes - kFrameHeaderBytes;
    std::vector<std::uint8_t> table(table_bytes + kFrameHeaderBytes);
    pread_exact(fd_, table.data(), table.size(), table_at, name_);
    if (get_le<std::uint32_t>(table.data()) != kZstdSeekTableMagic || get_le<std::uint32_t>(table.data() + 4) != table_bytes)
        bad("malformed seek table frame");
    std::uint64_t stored = 0, logical = 0;
    frames_.reserve(count);
    for (std::uint32_t i = 0; i < count; ++i) {
        const std::uint8_t* e = table.data() + kFrameHeaderBytes + i * entry_bytes;
        const std::uint32_t c = get_le<std::uint32_t>(e), d = get_le<std::uint32_t>(e + 4);
        // Sizes are checked before anything is allocated for them: a frame
        // holds at most 1 GiB (the zstd seekable format's own limit), the
        // header frame at most the largest .fft header.
        if (d > kMaxFrameBytes || (i == 1 && d > kFftFixedHeaderBytes + 8 * 255))
            bad("frame " + std::to_string(i) + " claims " + std::to_string(d) + " bytes");
        frames_.push_back({stored, c, logical, d});
        stored += c, logical += d;
        if (stored > table_at) bad("seek table frames run past the seek table");
    }
    if (stored != table_at) bad("seek table does not cover the file");
    logical_size_ = logical;

    // Frame 0: the descriptor.
    if (frames_.empty() || frames_[0].stored_size != kFrameHeaderBytes + kFftzDescriptorBytes || frames_[0].logical_size != 0)
        bad("missing FFTZ descriptor frame");
    std::uint8_t d[kFrameHeaderBytes + kFftzDescriptorBytes];
    pread_exact(fd_, d, sizeof d, 0, name_);
    if (!recognizes(d, sizeof d) || get_le<std::uint32_t>(d + 4) != kFftzDescriptorBytes) bad("bad FFTZ descriptor");
    const std::uint8_t* p = d + kFrameHeaderBytes;
    if (p[4] != kFftzVersion) bad("unsupported container version " + std::to_string(p[4]));
    if (p[5] > std::uint8_t(FftzLayout::transposed)) bad("unknown group layout " + std::to_string(p[5]));
    descriptor_.layout = FftzLayout(p[5]);
    descriptor_.group_blocks = get_le<std::uint32_t>(p + 8);
    if (descriptor_.group_blocks == 0) bad("zero blocks per group");
}

void FftzReader::check_layout(const FftHeader& h) {
    auto bad = [&](const std::string& what) {
        throw Error(Errc::fft_format, name_ + ": not a valid .fftz file: " + what);
    };
    block_bytes_ = h.block_bytes();
    direction_bits_ = h.direction_bits();
    groups_ = (std::uint64_t(h.blocks) + descriptor_.group_blocks - 1) / descriptor_.group_blocks;
    // Frames: descriptor, header, LUT, groups, [trailer].
    first_group_ = 3;
    if (frames_.size() < first_group_ + groups_ || frames_.size() > first_group_ + groups_ + 1)
        bad("expected " + std::to_string(first_group_ + groups_) + " frames and a trailer, found " +
            std::to_string(frames_.size()));
    if (frames_[1].logical_size != h.lut_offset()) bad("header frame size");
    if (frames_[2].logical_size != 8 * h.fibers) bad("LUT frame size");
    for (std::size_t g = 0; g < groups_; ++g) {
        const std::uint64_t blocks =
            std::min<std::uint64_t>(descriptor_.group_blocks, h.blocks - g * std::uint64_t(descriptor_.group_blocks));
        if (frames_[first_group_ + g].logical_size != blocks * block_bytes_)
            bad("group " + std::to_string(g) + " frame size");
    }
    std::lock_guard lock(mutex_);
    layout_checked_ = true;
    cached_ = SIZE_MAX;  // a group frame read with the header was not untransposed yet
}

const std::vector<std::uint8_t>& FftzReader::frame_bytes(std::size_t index) const {
    if (cached_ == index) return cache_;
    const Frame& f = frames_[index];
    std::vector<std::uint8_t> stored(f.stored_size);
    pread_exact(fd_, stored.data(), stored.size(), f.stored_at, name_);
    std::vector<std::uint8_t> out(f.logical_size);
    const std::size_t n = ZSTD_decompress(out.data(), out.size(), stored.data(), stored.size());
    // The seek table and frame headers were validated at open: a frame whose
    // content does not decompress (or fails zstd's content checksum) to the
    // size they give is damaged data, an integrity failure like a CSUM mismatch.
    if (ZSTD_isError(n) || n != f.logical_size)
        throw Error(Errc::checksum, name_ + ": frame " + std::to_string(index) + " is corrupted (zstd: " +
                                        (ZSTD_isError(n) ? ZSTD_getErrorName(n) : "wrong decompressed size") + ")");
    const bool group = layout_checked_ && index >= first_group_ && index < first_group_ + groups_;
    if (group && descriptor_.layout == FftzLayout::transposed)
        out = untranspose_block_group(out, direction_bits_, block_bytes_);
    cache_ = std::move(out);
    cached_ = index;
    return cache_;
}

void FftzReader::read(std::uint8_t* out, std::uint64_t size, std::uint64_t offset) const {
    if (offset > logical_size_ || size > logical_size_ - offset)
        throw Error(Errc::fft_format, name_ + ": not a valid .fftz file: read past the end of the content");
    std::lock_guard lock(mutex_);
    // The first frame ending after `offset`.
    auto it = std::upper_bound(frames_.begin(), frames_.end(), offset,
                               [](std::uint64_t o, const Frame& f) { return o < f.logical_at + f.logical_size; });
    while (size > 0) {
        if (it == frames_.end()) throw Error(Errc::fft_format, name_ + ": frames end before the content");
        if (it->logical_size == 0) {
            ++it;
            continue;
        }
        const auto& bytes = frame_bytes(std::size_t(it - frames_.begin()));
        const std::uint64_t in_frame = offset - it->logical_at;
        const std::uint64_t n = std::min(size, it->logical_size - in_frame);
        std::memcpy(out, bytes.data() + in_frame, n);
        out += n, size -= n, offset += n;
        ++it;
    }
}

}  // namespace fiblet::detail
