#include "fiblet/fft_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "core/bytes.hpp"
#include "fiblet/error.hpp"
#include "io/fftz_reader.hpp"

namespace fiblet {
using detail::get_le;

namespace {

[[noreturn]] void bad(const std::string& name, const std::string& what) {
    throw Error(Errc::fft_format, name + ": not a valid .fft file: " + what);
}

void pread_all(int fd, std::uint8_t* out, std::uint64_t size, std::uint64_t offset, const std::string& name) {
    while (size > 0) {
        const ssize_t n = ::pread(fd, out, size, off_t(offset));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw Error(Errc::io, name + ": read failed: " + std::strerror(errno));
        if (n == 0) bad(name, "unexpected end of file");
        out += n, size -= std::uint64_t(n), offset += std::uint64_t(n);
    }
}

}  // namespace

FftHeader parse_fft_header(std::span<const std::uint8_t> b, std::uint64_t file_size, const std::string& name) {
    if (b.size() < kFftFixedHeaderBytes) bad(name, "truncated header (" + std::to_string(b.size()) + " bytes)");
    FftHeader h;
    const std::uint8_t* p = b.data();
    h.version = p[0];
    if (h.version != kFftVersion && h.version != kFft16Version)
        bad(name, "unsupported version " + std::to_string(h.version) + " (fiblet reads versions 2 and 16)");
    h.fibers = get_le<std::uint64_t>(p + 1);
    h.points = get_le<std::uint64_t>(p + 9);
    h.blocks = get_le<std::uint32_t>(p + 17);
    h.points_per_block = get_le<std::uint32_t>(p + 21);
    h.scaling = get_le<float>(p + 25);
    for (int i = 0; i < 3; ++i) h.offset[i] = get_le<float>(p + 29 + 4 * i);
    h.ratio = get_le<float>(p + 41);
    h.step = get_le<float>(p + 45);
    h.max_error_mm = get_le<float>(p + 49);
    h.mean_error_mm = get_le<float>(p + 53);
    const unsigned buffers = p[57];

    if (h.points_per_block < 2 || h.points_per_block > h.max_points_per_block())
        bad(name, "points per block " + std::to_string(h.points_per_block) + " outside [2, " +
                      std::to_string(h.max_points_per_block()) + "]");
    if (!(std::isfinite(h.scaling) && h.scaling > 0)) bad(name, "scaling is not a positive finite number");
    for (float o : h.offset)
        if (!std::isfinite(o)) bad(name, "offset is not finite");
    if (!(std::isfinite(h.ratio) && h.ratio > 0 && h.ratio <= 2)) bad(name, "ratio outside (0, 2]");
    if (!(std::isfinite(h.step) && h.step >= 0 && h.step < 1)) bad(name, "step outside [0, 1)");
    // Counts are checked against the file size before anything is allocated.
    const std::uint64_t fixed = kFftFixedHeaderBytes + 8ull * buffers;
    if (b.size() < fixed) bad(name, "truncated buffer table");
    for (unsigned i = 0; i < buffers; ++i) h.buffer_ends.push_back(get_le<std::uint64_t>(p + kFftFixedHeaderBytes + 8 * i));
    if (h.fibers > (file_size - std::min(file_size, fixed)) / 8)
        bad(name, "fiber count " + std::to_string(h.fibers) + " exceeds the file size");
    if (std::uint64_t{h.blocks} * h.block_bytes() > file_size - std::min(file_size, fixed + 8 * h.fibers))
        bad(name, "block count " + std::to_string(h.blocks) + " exceeds the file size (truncated blocks?)");
    if (h.blocks > 0 && buffers == 0) bad(name, "blocks but no buffer table");
    std::uint64_t prev = 0;
    for (std::uint64_t e : h.buffer_ends) {
        if (e < prev || e - prev > fft_max_blocks_per_buffer(h.block_bytes())) bad(name, "inconsistent buffer table");
        prev = e;
    }
    if (buffers > 0 && prev != h.blocks) bad(name, "buffer table does not end at the block count");
    if (h.points > std::uint64_t{h.blocks} * h.points_per_block) bad(name, "point count exceeds the blocks' capacity");
    if (h.points < h.blocks) bad(name, "fewer points than blocks");
    return h;
}

FftFile::FftFile(const std::string& path) : path_(path) {
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
        ::close(fd_);
        throw Error(Errc::io, path + ": not a regular file");
    }
    file_size_ = logical_size_ = std::uint64_t(st.st_size);
    try {
        std::uint8_t magic[12] = {};
        if (file_size_ >= sizeof magic) pread_all(fd_, magic, sizeof magic, 0, path);
        if (detail::FftzReader::recognizes(magic, file_size_ >= sizeof magic ? sizeof magic : 0)) {
            fftz_ = std::make_unique<detail::FftzReader>(fd_, file_size_, path);
            logical_size_ = fftz_->logical_size();
        }
        std::vector<std::uint8_t> head(std::min<std::uint64_t>(logical_size_, kFftFixedHeaderBytes + 8 * 255));
        read_at(head.data(), head.size(), 0);
        header_ = parse_fft_header(head, logical_size_, path);
        if (fftz_) fftz_->check_layout(header_);

        std::vector<std::uint8_t> raw(8 * header_.fibers);
        read_at(raw.data(), raw.size(), header_.lut_offset());
        lut_.resize(header_.fibers);
        fiber_first_block_.resize(header_.fibers);
        std::uint64_t next = 0;  // fibers are stored in order, their blocks contiguous
        for (std::uint64_t i = 0; i < header_.fibers; ++i) {
            lut_[i] = {get_le<std::uint32_t>(&raw[8 * i]), get_le<std::uint32_t>(&raw[8 * i + 4])};
            const std::uint32_t buffer = lut_[i].buffer();
            if (buffer >= header_.buffer_ends.size() && lut_[i].block_count() > 0)
                bad(path, "fiber " + std::to_string(i) + " points to buffer " + std::to_string(buffer) +
                              " past the buffer table");
            const std::uint64_t base = buffer == 0 || buffer > header_.buffer_ends.size()
                                           ? 0
                                           : header_.buffer_ends[buffer - 1];
            const std::uint64_t first = base + lut_[i].y;
            if (lut_[i].block_count() > 0 && first != next)
                bad(path, "fiber " + std::to_string(i) + " LUT entry points to block " + std::to_string(first) +
                              ", expected " + std::to_string(next));
            fiber_first_block_[i] = next;
            next += lut_[i].block_count();
            if (next > header_.blocks)
                bad(path, "fiber " + std::to_string(i) + " LUT entry points past the last block");
        }
        if (next != header_.blocks)
            bad(path, "the fiber LUT covers " + std::to_string(next) + " blocks, the header says " +
                          std::to_string(header_.blocks));
        read_trailer();
    } catch (...) {
        fftz_.reset();
        ::close(fd_);
        fd_ = -1;
        throw;
    }
}

void FftFile::read_at(std::uint8_t* out, std::uint64_t size, std::uint64_t offset) const {
    if (fftz_) fftz_->read(out, size, offset);
    else pread_all(fd_, out, size, offset, path_);
}

void FftFile::read_trailer() {
    const std::uint64_t end = header_.file_bytes();
    if (logical_size_ < end + kTrailerFooterBytes) return;  // no trailer: a plain version-2 file
    std::uint8_t footer[kTrailerFooterBytes];
    read_at(footer, sizeof footer, logical_size_ - sizeof footer);
    if (std::memcmp(footer + 8, kTrailerMagic, 8) != 0) return;  // foreign trailing bytes: ignored
    if (get_le<std::uint64_t>(footer) != end) bad(path_, "trailer does not start after the last block");
    std::uint64_t pos = end;
    const std::uint64_t stop = logical_size_ - kTrailerFooterBytes;
    while (pos < stop) {
        std::uint8_t head[16];
        if (stop - pos < sizeof head) bad(path_, "truncated trailer chunk header");
        read_at(head, sizeof head, pos);
        const std::uint64_t size = get_le<std::uint64_t>(head + 8);
        if (size > stop - pos - sizeof head) bad(path_, "trailer chunk runs past the footer");
        TrailerChunk chunk;
        std::memcpy(chunk.tag.data(), head, 4);
        chunk.payload.resize(size);
        read_at(chunk.payload.data(), size, pos + sizeof head);
        trailer_.push_back(std::move(chunk));
        pos += sizeof head + size;
    }
}

const TrailerChunk* FftFile::find_chunk(std::array<char, 4> tag) const {
    for (const auto& c : trailer_)
        if (c.tag == tag) return &c;
    return nullptr;
}

std::vector<std::pair<std::string, std::string>> FftFile::properties() const {
    std::vector<std::pair<std::string, std::string>> props;
    const TrailerChunk* c = find_chunk(kPropertiesTag);
    if (!c) return props;
    // Pairs of length-prefixed strings: u32 size, bytes (key, then value).
    const auto& p = c->payload;
    std::size_t pos = 0;
    auto next_string = [&](std::string& s) {
        if (p.size() - pos < 4) return false;
        const std::uint32_t n = get_le<std::uint32_t>(&p[pos]);
        if (p.size() - pos - 4 < n) return false;
        s.assign(reinterpret_cast<const char*>(&p[pos + 4]), n);
        pos += 4 + n;
        return true;
    };
    std::string key, value;
    while (pos < p.size()) {
        if (!next_string(key) || !next_string(value)) bad(path_, "malformed PROP chunk");
        props.emplace_back(key, value);
    }
    return props;
}

FftFile::~FftFile() {
    if (fd_ >= 0) ::close(fd_);
}

FftFile::FftFile(FftFile&& o) noexcept
    : path_(std::move(o.path_)), fd_(o.fd_), file_size_(o.file_size_), logical_size_(o.logical_size_),
      fftz_(std::move(o.fftz_)), header_(std::move(o.header_)),
      lut_(std::move(o.lut_)), fiber_first_block_(std::move(o.fiber_first_block_)), trailer_(std::move(o.trailer_)) {
    o.fd_ = -1;
}

FftFile& FftFile::operator=(FftFile&& o) noexcept {
    if (this != &o) {
        if (fd_ >= 0) ::close(fd_);
        path_ = std::move(o.path_);
        fd_ = o.fd_;
        o.fd_ = -1;
        file_size_ = o.file_size_;
        logical_size_ = o.logical_size_;
        fftz_ = std::move(o.fftz_);
        header_ = std::move(o.header_);
        lut_ = std::move(o.lut_);
        fiber_first_block_ = std::move(o.fiber_first_block_);
        trailer_ = std::move(o.trailer_);
    }
    return *this;
}

void FftFile::read_blocks(std::uint64_t first, std::uint64_t count, std::uint8_t* out) const {
    if (first > header_.blocks || count > header_.blocks - first)
        throw Error(Errc::invalid_argument, path_ + ": block range past the end");
    const std::uint64_t bb = header_.block_bytes();
    read_at(out, count * bb, header_.blocks_offset() + first * bb);
}

std::vector<std::uint8_t> FftFile::read_blocks(std::uint64_t first, std::uint64_t count) const {
    std::vector<std::uint8_t> out(count * header_.block_bytes());
    read_blocks(first, count, out.data());
    return out;
}

}  // namespace fiblet
