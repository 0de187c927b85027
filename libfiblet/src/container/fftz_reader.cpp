#include "container/fftz_reader.hpp"

#include <unistd.h>
#include <zstd.h>
#include <zstd_errors.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>
#include <new>

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
    // Block groups are whole fixed-size blocks: 16-bit containers hold version 16.
    if (h.packed()) bad("holds a version-17 .fft (packed blocks); 16-bit containers hold version 16");
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

// One frame decompressed as a stream: its stored bytes are read a slice at
// a time and its content produced on demand. Damage (a zstd error, a content
// checksum mismatch, content shorter or longer than the seek table says, or
// bytes after the frame) is an integrity failure.
class FftzReader::FrameStream {
public:
    FrameStream(const FftzReader& r, std::size_t index)
        : r_(r), index_(index), frame_(r.frames_[index]), ds_(ZSTD_createDStream()) {
        if (!ds_) throw std::bad_alloc();
        ZSTD_initDStream(ds_);
    }
    ~FrameStream() { ZSTD_freeDStream(ds_); }
    FrameStream(const FrameStream&) = delete;
    FrameStream& operator=(const FrameStream&) = delete;

    std::size_t index() const { return index_; }
    std::uint64_t position() const { return produced_; }

    // Fills out[0, size) with the next bytes of the frame's content.
    void read(std::uint8_t* out, std::uint64_t size) {
        if (size > frame_.logical_size - produced_) damaged("content continues past its size in the seek table");
        ZSTD_outBuffer o{out, std::size_t(size), 0};
        while (o.pos < o.size) {
            if (in_.pos == in_.size) refill();
            const std::size_t rc = ZSTD_decompressStream(ds_, &o, &in_);
            if (ZSTD_isError(rc)) damaged(ZSTD_getErrorName(rc));
            ended_ = rc == 0;
            if (ended_ && o.pos < o.size) damaged("content shorter than its size in the seek table");
        }
        produced_ += size;
    }
    // After the last byte: the frame must end here, and so must its stored bytes.
    void finish() {
        std::uint8_t extra;
        ZSTD_outBuffer o{&extra, 1, 0};
        while (!ended_) {
            if (in_.pos == in_.size && consumed_ < frame_.stored_size) refill();
            const std::size_t rc = ZSTD_decompressStream(ds_, &o, &in_);
            if (ZSTD_isError(rc)) damaged(ZSTD_getErrorName(rc));
            if (o.pos > 0) damaged("content longer than its size in the seek table");
            ended_ = rc == 0;
            if (!ended_ && in_.pos == in_.size && consumed_ == frame_.stored_size) damaged("truncated frame");
        }
        if (in_.pos != in_.size || consumed_ != frame_.stored_size) damaged("bytes after the end of the zstd frame");
    }

private:
    [[noreturn]] void damaged(const std::string& what) const { r_.damaged_frame(index_, what); }
    void refill() {
        if (consumed_ == frame_.stored_size) damaged("truncated frame");
        buffer_.resize(std::size_t(std::min<std::uint64_t>(1u << 17, frame_.stored_size - consumed_)));
        pread_exact(r_.fd_, buffer_.data(), buffer_.size(), frame_.stored_at + consumed_, r_.name_);
        consumed_ += buffer_.size();
        in_ = {buffer_.data(), buffer_.size(), 0};
    }

    const FftzReader& r_;
    std::size_t index_;
    Frame frame_;
    ZSTD_DStream* ds_;
    std::vector<std::uint8_t> buffer_;
    ZSTD_inBuffer in_{nullptr, 0, 0};
    std::uint64_t consumed_ = 0, produced_ = 0;
    bool ended_ = false;  // the zstd frame (and its content checksum) is complete
};

FftzReader::~FftzReader() = default;

void FftzReader::FreeDCtx::operator()(ZSTD_DCtx_s* d) const { ZSTD_freeDCtx(d); }

void FftzReader::damaged_frame(std::size_t index, const std::string& what) const {
    throw Error(Errc::checksum, name_ + ": damaged .fftz frame " + std::to_string(index) + ": " + what);
}

void FftzReader::decompress_whole(std::size_t index, std::vector<std::uint8_t>& out) const {
    const Frame& f = frames_[index];
    stored_.resize(std::size_t(f.stored_size));
    pread_exact(fd_, stored_.data(), stored_.size(), f.stored_at, name_);
    const std::size_t frame = ZSTD_findFrameCompressedSize(stored_.data(), stored_.size());
    if (ZSTD_isError(frame)) damaged_frame(index, ZSTD_getErrorName(frame));
    if (frame != stored_.size()) damaged_frame(index, "bytes after the end of the zstd frame");
    if (!dctx_) {
        dctx_.reset(ZSTD_createDCtx());
        if (!dctx_) throw std::bad_alloc();
    }
    out.resize(std::size_t(f.logical_size));
    const std::size_t n = ZSTD_decompressDCtx(dctx_.get(), out.data(), out.size(), stored_.data(), stored_.size());
    if (ZSTD_isError(n))
        damaged_frame(index, ZSTD_getErrorCode(n) == ZSTD_error_dstSize_tooSmall
                                 ? "content longer than its size in the seek table"
                                 : ZSTD_getErrorName(n));
    if (n != out.size()) damaged_frame(index, "content shorter than its size in the seek table");
}

const std::vector<std::uint8_t>& FftzReader::frame_bytes(std::size_t index) const {
    if (cached_ == index) return cache_;
    const Frame& f = frames_[index];
    // Small frames in one call; larger ones grown as the content really
    // arrives, beyond what is kept from the last frame: a frame that claims
    // far more than it holds fails before the claim is allocated. The
    // buffers are reused from frame to frame (groups are all the same size
    // but the last).
    const bool group = layout_checked_ && index >= first_group_ && index < first_group_ + groups_;
    const bool transposed = group && descriptor_.layout == FftzLayout::transposed;
    std::vector<std::uint8_t>& out = transposed ? fields_ : cache_;
    cached_ = SIZE_MAX;  // until the frame is whole
    const std::size_t size = std::size_t(f.logical_size);
    if (f.logical_size <= kOneShotFrameBytes && f.stored_size <= ZSTD_compressBound(size)) {
        decompress_whole(index, out);
    } else {
        FrameStream stream(*this, index);
        for (std::size_t done = 0; done < size;) {
            const std::size_t end = std::size_t(std::min<std::uint64_t>(size, std::max<std::uint64_t>(2 * done, 1u << 16)));
            if (out.size() < end) out.resize(end);
            stream.read(out.data() + done, end - done);
            done = end;
        }
        stream.finish();
        out.resize(size);
    }
    if (transposed) {
        cache_.resize(size);
        untranspose_block_group(fields_, direction_bits_, block_bytes_, cache_);
    }
    cached_ = index;
    return cache_;
}

void FftzReader::read_streamed(std::size_t index, std::uint64_t at, std::uint8_t* out, std::uint64_t size) const {
    if (!stream_ || stream_->index() != index || stream_->position() > at)
        stream_ = std::make_unique<FrameStream>(*this, index);
    std::vector<std::uint8_t> skip;
    while (stream_->position() < at) {
        skip.resize(std::size_t(std::min<std::uint64_t>(at - stream_->position(), 1u << 20)));
        stream_->read(skip.data(), skip.size());
    }
    stream_->read(out, size);
    if (stream_->position() == frames_[index].logical_size) stream_->finish(), stream_.reset();
}

void FftzReader::check_lut_content() const {
    std::lock_guard lock(mutex_);
    FrameStream stream(*this, kLutFrame);
    std::vector<std::uint8_t> scratch(1u << 20);
    for (std::uint64_t left = frames_[kLutFrame].logical_size; left > 0;) {
        const std::uint64_t n = std::min<std::uint64_t>(left, scratch.size());
        stream.read(scratch.data(), n);
        left -= n;
    }
    stream.finish();
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
        const auto index = std::size_t(it - frames_.begin());
        const std::uint64_t in_frame = offset - it->logical_at;
        const std::uint64_t n = std::min(size, it->logical_size - in_frame);
        // The LUT is read once, in order, by the FftFile that opens this:
        // streamed, it costs no copy; block groups are untransposed whole.
        const bool group = index >= first_group_ && index < first_group_ + groups_;
        if (index == kLutFrame || (it->logical_size > kMaxCachedFrame && !group)) {
            read_streamed(index, in_frame, out, n);
        } else {
            const auto& bytes = frame_bytes(index);
            std::memcpy(out, bytes.data() + in_frame, n);
        }
        out += n, size -= n, offset += n;
        ++it;
    }
}

}  // namespace fiblet::detail
