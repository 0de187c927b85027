#include "fiblet/fft_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <mutex>
#include <utility>

#include "core/bytes.hpp"
#include "fiblet/error.hpp"
#include "container/packed_blocks16.hpp"
#include "container/fft_trailer.hpp"
#include "fiblet/tractogram_format.hpp"
#include "container/fftz_reader.hpp"
#include "io/mapped_copy.hpp"
#include "io/open_inputs.hpp"
#include "io/regular_input.hpp"

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
    if (h.version != kFftVersion && h.version != kFft16Version && h.version != kFft16PackedVersion) {
        const TractogramFormat other = detect_tractogram_format(name);  // a .trk, .tck... given for a .fft
        if (other != TractogramFormat::unknown && other != TractogramFormat::fft && other != TractogramFormat::fftz)
            throw Error(Errc::unsupported, name + ": " + tractogram_format_description(other) +
                                               ", not a .fft file (compress it into one first)");
        bad(name, "unsupported version " + std::to_string(h.version) + " (fiblet reads versions 2, 16 and 17)");
    }
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
    // A step may exceed the box (two points on its diagonal are sqrt(3) apart), never by much.
    if (!(std::isfinite(h.step) && h.step >= 0 && h.step <= 16)) bad(name, "step outside [0, 16]");
    // Counts are checked against the file size before anything is allocated.
    const std::uint64_t fixed = kFftFixedHeaderBytes + 8ull * buffers;
    if (b.size() < fixed) bad(name, "truncated buffer table");
    for (unsigned i = 0; i < buffers; ++i) h.buffer_ends.push_back(get_le<std::uint64_t>(p + kFftFixedHeaderBytes + 8 * i));
    if (h.fibers > (file_size - std::min(file_size, fixed)) / 8)
        bad(name, "fiber count " + std::to_string(h.fibers) + " exceeds the file size");
    // Packed blocks (version 17) hold at least their anchors; their exact size follows from the LUT.
    const std::uint64_t least_block_bytes = h.packed() ? kPacked16AnchorBytes : h.block_bytes();
    if (std::uint64_t{h.blocks} * least_block_bytes > file_size - std::min(file_size, fixed + 8 * h.fibers))
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

struct FftFile::Mapping {
    std::once_flag once;
    void* address = nullptr;
    std::size_t length = 0;
    std::size_t skip = 0;  // from the page boundary to the first block
    ~Mapping() {
        if (address) ::munmap(address, length);
    }
};

FftFile::FftFile(const std::string& path, FftOpenOptions options)
    : path_(path), options_(options), mapping_(std::make_unique<Mapping>()) {
    detail::require_regular_input(path);
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw Error(Errc::io, path + ": cannot open: " + std::strerror(errno));
    input_ = std::make_unique<detail::InputRegistration>(fd_);
    try {
        struct stat st {};
        if (::fstat(fd_, &st) != 0) throw Error(Errc::io, path + ": cannot stat: " + std::strerror(errno));
        // Blocks are read by offset (random access): a pipe cannot be.
        if (!S_ISREG(st.st_mode))
            throw Error(Errc::io, path + ": not a regular file (a pipe or a device?): a .fft input is read by offset, "
                                         "save it to a file first");
        file_size_ = logical_size_ = std::uint64_t(st.st_size);
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
        std::uint64_t lut_hash = 0;
        read_lut(lut_hash);
        if (!options_.ignore_trailer) open_trailer(std::span(head).first(std::size_t(header_.lut_offset())), lut_hash);
    } catch (...) {
        close();
        throw;
    }
}

// Reads and validates the LUT a slice at a time (no second copy of it in
// memory), hashing its bytes for the checksum check.
void FftFile::read_lut(std::uint64_t& lut_hash) {
    constexpr std::uint64_t kSliceEntries = 1u << 16;
    // A plain file holds its LUT (the size was checked against the file's);
    // a .fftz's LUT frame is decompressed once first, in bounded memory, so
    // that a frame claiming more than it holds fails before the claim is
    // allocated.
    if (fftz_) fftz_->check_lut_content();
    lut_.resize(header_.fibers);
    fiber_first_block_.resize(header_.fibers);
    if (header_.packed()) fiber_points_.resize(header_.fibers), fiber_offset_.resize(header_.fibers);
    std::vector<std::uint8_t> raw;
    Xxh64Stream hash;
    std::uint64_t next = 0;  // fibers are stored in order, their blocks contiguous
    for (std::uint64_t s = 0; s < header_.fibers; s += kSliceEntries) {
        const std::uint64_t n = std::min(kSliceEntries, header_.fibers - s);
        raw.resize(8 * n);
        read_at(raw.data(), raw.size(), header_.lut_offset() + 8 * s);
        hash.update(raw.data(), raw.size());
        for (std::uint64_t j = 0; j < n; ++j) {
            const std::uint64_t i = s + j;
            lut_[i] = {get_le<std::uint32_t>(&raw[8 * j]), get_le<std::uint32_t>(&raw[8 * j + 4])};
            const std::uint32_t buffer = lut_[i].buffer();
            if (buffer >= header_.buffer_ends.size() && lut_[i].block_count() > 0)
                bad(path_, "fiber " + std::to_string(i) + " points to buffer " + std::to_string(buffer) +
                               " past the buffer table");
            const std::uint64_t base =
                buffer == 0 || buffer > header_.buffer_ends.size() ? 0 : header_.buffer_ends[buffer - 1];
            if (header_.packed()) read_packed_lut_entry(i, base, next);
            const std::uint64_t first = base + lut_[i].y;
            if (lut_[i].block_count() > 0 && first != next)
                bad(path_, "fiber " + std::to_string(i) + " LUT entry points to block " + std::to_string(first) +
                               ", expected " + std::to_string(next));
            fiber_first_block_[i] = std::uint32_t(next);  // next <= blocks, a u32 (checked below)
            next += lut_[i].block_count();
            if (next > header_.blocks)
                bad(path_, "fiber " + std::to_string(i) + " LUT entry points past the last block");
        }
    }
    if (next != header_.blocks)
        bad(path_, "the fiber LUT covers " + std::to_string(next) + " blocks, the header says " +
                       std::to_string(header_.blocks));
    if (header_.packed()) {
        if (packed_points_ != header_.points)
            bad(path_, "the fiber LUT counts " + std::to_string(packed_points_) + " points, the header says " +
                           std::to_string(header_.points));
        header_.packed_block_bytes = packed_bytes_;
        if (header_.file_bytes() > logical_size_)
            bad(path_, "the packed blocks need " + std::to_string(packed_bytes_) +
                           " bytes, more than the file holds (truncated blocks?)");
    }
    lut_hash = hash.digest();
}

// Version 17: the LUT's second word is the fiber's point count. It fixes
// the block count and where the fiber's packed blocks start; in memory the
// entry becomes the version-16 one (first block inside its buffer).
void FftFile::read_packed_lut_entry(std::uint64_t i, std::uint64_t base, std::uint64_t next) {
    const std::uint32_t points = lut_[i].y, ppb = header_.points_per_block;
    const std::uint64_t blocks = (std::uint64_t{points} + ppb - 1) / ppb;
    if (blocks != lut_[i].block_count())
        bad(path_, "fiber " + std::to_string(i) + " LUT entry: " + std::to_string(points) + " points in " +
                       std::to_string(lut_[i].block_count()) + " blocks of " + std::to_string(ppb));
    if (blocks > 0 && next < base)
        bad(path_, "fiber " + std::to_string(i) + " LUT entry starts before its buffer");
    fiber_points_[i] = points;
    fiber_offset_[i] = packed_bytes_;
    packed_points_ += points;
    if (blocks > 0)
        packed_bytes_ += (blocks - 1) * packed16_block_bytes(ppb) +
                         packed16_block_bytes(points - std::uint32_t(blocks - 1) * ppb);
    lut_[i].y = std::uint32_t(blocks > 0 ? next - base : 0);
}

void FftFile::read_at(std::uint8_t* out, std::uint64_t size, std::uint64_t offset) const {
    if (fftz_) fftz_->read(out, size, offset);
    else pread_all(fd_, out, size, offset, path_);
}

// The trailer in three stages: its chunks (a damaged trailer is an integrity
// failure), the checksums of everything read so far, then the values of the
// chunks, so that damage the checksums cover is reported as damage.
void FftFile::open_trailer(std::span<const std::uint8_t> head, std::uint64_t lut_hash) {
    detail::TrailerChunks t = detail::read_trailer_chunks(
        [this](std::uint8_t* out, std::uint64_t size, std::uint64_t offset) { read_at(out, size, offset); },
        header_.file_bytes(), logical_size_, header_.fibers, path_);
    trailer_ = std::move(t.chunks);
    trailer_hash_ = t.hash_before_checksum;
    if (const TrailerChunk* c = find_chunk(kChecksumTag)) checksums_ = FftChecksums::parse(*c, header_.blocks, path_);
    if (verifies_checksums()) {
        verify_open_checksums(head, lut_hash);
        const std::uint64_t words = (checksums_->group_hashes.size() + 63) / 64;
        verified_groups_ = std::make_unique<std::atomic<std::uint64_t>[]>(words);
        for (std::uint64_t i = 0; i < words; ++i) verified_groups_[i].store(0, std::memory_order_relaxed);
    }
    detail::TrailerValues values = detail::validate_trailer_chunks(trailer_, header_, path_);
    properties_ = std::move(values.properties);
    resampling_ = values.resampling;
    end_fractions_ = std::move(values.end_fractions);
    fields_ = std::move(values.fields);
}

const std::vector<StreamlineField>& FftFile::streamline_fields() const {
    static const std::vector<StreamlineField> none;
    return fields_ ? *fields_ : none;
}

void FftFile::verify_open_checksums(std::span<const std::uint8_t> head, std::uint64_t lut_hash) const {
    const FftChecksums& c = *checksums_;
    auto fail = [&](const std::string& what) {
        throw Error(Errc::checksum, path_ + ": checksum mismatch in the " + what + ": the file is corrupted");
    };
    if (xxh64(head.data(), head.size()) != c.header_hash) fail("header");
    if (lut_hash != c.lut_hash) fail("fiber LUT");
    if (trailer_hash_ != c.trailer_hash) fail("trailer chunks");  // hashed as the chunks were read
}

const TrailerChunk* FftFile::find_chunk(std::array<char, 4> tag) const {
    for (const auto& c : trailer_)
        if (c.tag == tag) return &c;
    return nullptr;
}

void FftFile::close() noexcept {
    fftz_.reset();
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
}

FftFile::~FftFile() { close(); }

FftFile::FftFile(FftFile&& o) noexcept { *this = std::move(o); }

FftFile& FftFile::operator=(FftFile&& o) noexcept {
    if (this != &o) {
        close();
        path_ = std::move(o.path_);
        options_ = o.options_;
        fd_ = std::exchange(o.fd_, -1);
        file_size_ = o.file_size_;
        logical_size_ = o.logical_size_;
        fftz_ = std::move(o.fftz_);
        header_ = std::move(o.header_);
        lut_ = std::move(o.lut_);
        fiber_first_block_ = std::move(o.fiber_first_block_);
        fiber_points_ = std::move(o.fiber_points_);
        fiber_offset_ = std::move(o.fiber_offset_);
        packed_points_ = o.packed_points_;
        packed_bytes_ = o.packed_bytes_;
        trailer_ = std::move(o.trailer_);
        properties_ = std::move(o.properties_);
        resampling_ = o.resampling_;
        trailer_hash_ = o.trailer_hash_;
        checksums_ = std::move(o.checksums_);
        end_fractions_ = std::move(o.end_fractions_);
        fields_ = std::move(o.fields_);
        verified_groups_ = std::move(o.verified_groups_);
        mapping_ = std::move(o.mapping_);
        input_ = std::move(o.input_);
    }
    return *this;
}

void FftFile::require_block_range(std::uint64_t first, std::uint64_t count) const {
    if (first > header_.blocks || count > header_.blocks - first)
        throw Error(Errc::invalid_argument, path_ + ": block range past the end");
}

void FftFile::read_blocks(std::uint64_t first, std::uint64_t count, std::uint8_t* out) const {
    require_block_range(first, count);
    if (count == 0) return;
    if (!header_.packed()) {
        read_at(out, count * header_.block_bytes(), header_.blocks_offset() + first * header_.block_bytes());
        check_block_structure(first, count, out, fiber_of_block(first));
        if (verifies_checksums()) verify_block_groups(first, count, out);
        return;
    }
    // Version 17: read packed, expand (which checks the codes), check, and
    // verify the groups over the packed bytes (fft-checksum.md), so the
    // blocks of a group outside the range are hashed, not expanded.
    thread_local std::vector<std::uint8_t> stored;
    const std::uint64_t begin = stored_offset(first);
    stored.resize(stored_offset(first + count) - begin);
    read_at(stored.data(), stored.size(), header_.blocks_offset() + begin);
    expand_packed_blocks(first, count, stored.data(), out);
    check_block_structure(first, count, out, fiber_of_block(first));
    if (verifies_checksums()) verify_block_groups(first, count, stored.data());
    if (stored.capacity() > (std::size_t{16} << 20)) std::vector<std::uint8_t>().swap(stored);  // a whole-file read: let it go
}

std::uint64_t FftFile::fiber_of_block(std::uint64_t block) const {
    // The last fiber starting at or before it (an empty fiber shares its
    // successor's first block, so it is skipped).
    return std::uint64_t(std::upper_bound(fiber_first_block_.begin(), fiber_first_block_.end(),
                                          std::uint32_t(block)) -
                         fiber_first_block_.begin()) -
           1;
}

std::uint64_t FftFile::stored_offset(std::uint64_t block) const {
    if (!header_.packed()) return block * header_.block_bytes();
    if (block == header_.blocks) return packed_bytes_;
    const std::uint64_t f = fiber_of_block(block);
    return fiber_offset_[f] + (block - fiber_first_block_[f]) * packed16_block_bytes(header_.points_per_block);
}

// Packed blocks [first, first + count) at `packed` into the in-memory layout.
void FftFile::expand_packed_blocks(std::uint64_t first, std::uint64_t count, const std::uint8_t* packed,
                                   std::uint8_t* out) const {
    const std::uint64_t bb = header_.block_bytes();
    const std::uint32_t ppb = header_.points_per_block;
    std::uint64_t f = fiber_of_block(first), k = first - fiber_first_block_[f];
    const std::uint8_t* p = packed;
    for (std::uint64_t b = 0; b < count; ++b, ++k) {
        while (k >= lut_[f].block_count()) ++f, k = 0;
        const std::uint32_t blocks_in_fiber = lut_[f].block_count();
        const detail::PackedBlockPlace place{
            k + 1 < blocks_in_fiber ? ppb : fiber_points_[f] - std::uint32_t(k) * ppb, std::uint32_t(f), k == 0,
            k + 1 == blocks_in_fiber};
        const std::string problem = detail::expand_block16(header_, p, place, out + b * bb);
        if (!problem.empty())
            bad(path_, "block " + std::to_string(first + b) + " (block " + std::to_string(k) + " of fiber " +
                           std::to_string(f) + "): " + problem);
        p += packed16_block_bytes(place.points);
    }
}

void FftFile::check_block_structure(std::uint64_t first, std::uint64_t count, const std::uint8_t* blocks,
                                    std::uint64_t fiber) const {
    const std::uint32_t bb = header_.block_bytes();
    std::uint64_t f = fiber, k = first - fiber_first_block_[f];
    for (std::uint64_t b = 0; b < count; ++b, ++k) {
        while (k >= lut_[f].block_count()) ++f, k = 0;
        const BlockFlags v = block_flags(header_, blocks + b * bb);
        const std::uint32_t n = v.point_count, blocks_in_fiber = lut_[f].block_count();
        const auto where = [&] {
            return "block " + std::to_string(first + b) + " (block " + std::to_string(k) + " of " +
                   std::to_string(blocks_in_fiber) + " of fiber " + std::to_string(f) + ")";
        };
        if (n == 0 || n > header_.points_per_block)
            bad(path_, where() + " holds " + std::to_string(n) + " points (allowed 1.." +
                           std::to_string(header_.points_per_block) + ")");
        if (v.first != (k == 0) || v.last != (k + 1 == blocks_in_fiber))
            bad(path_, where() + " has first/last flags inconsistent with the fiber LUT");
        // A block moved within or across fibers keeps its own identity bytes.
        if (v.fiber_id != std::uint32_t(f))  // IDs are u32: fibers past 2^32 wrap
            bad(path_, where() + " carries fiber ID " + std::to_string(v.fiber_id) + " (moved or damaged block)");
        if (v.index_in_fiber && *v.index_in_fiber != k % 256)
            bad(path_, where() + " carries block index " + std::to_string(*v.index_in_fiber) +
                           " (moved or damaged block)");
    }
}

// Whether checksum groups [g0, g1) were all verified by earlier reads.
bool FftFile::groups_verified(std::uint64_t g0, std::uint64_t g1) const {
    for (std::uint64_t g = g0; g < g1; ++g)
        if (!(verified_groups_[g / 64].load(std::memory_order_acquire) >> (g % 64) & 1)) return false;
    return true;
}

// `blocks`: blocks [first, first + count) as stored (packed for version 17).
void FftFile::verify_block_groups(std::uint64_t first, std::uint64_t count, const std::uint8_t* blocks) const {
    const FftChecksums& c = *checksums_;
    const std::uint64_t g_blocks = c.group_blocks, end = first + count;
    if (count == 0) return;
    const std::uint64_t g_begin = first / g_blocks, g_end = (end - 1) / g_blocks + 1;  // the groups read
    if (groups_verified(g_begin, g_end)) return;  // most reads after the first
    const std::uint64_t base = stored_offset(first);
    std::vector<std::uint8_t> edge;  // the part of a group outside [first, end)
    std::optional<Xxh64Stream> hash;  // made for the first group not verified yet (most reads find none)
    // Hashed in place in the mapping when the file has one (no copy), else read.
    auto hash_from_file = [&](std::uint64_t b0, std::uint64_t b1) {
        const std::uint64_t at = stored_offset(b0), size = stored_offset(b1) - at;
        if (const std::uint8_t* mapped = mapped_first_block()) {
            if (!detail::hash_from_mapping(mapped + at, size, *hash)) shrank_while_read();
            require_size(header_.blocks_offset() + at + size);
            return;
        }
        edge.resize(size);
        read_at(edge.data(), edge.size(), header_.blocks_offset() + at);
        hash->update(edge.data(), edge.size());
    };
    for (std::uint64_t g = g_begin; g < g_end; ++g) {
        std::atomic<std::uint64_t>& word = verified_groups_[g / 64];
        const std::uint64_t bit = std::uint64_t{1} << (g % 64);
        if (word.load(std::memory_order_acquire) & bit) continue;  // checked by an earlier read
        const std::uint64_t g0 = g * g_blocks, g1 = std::min(g0 + g_blocks, std::uint64_t{header_.blocks});
        if (hash) hash->reset();
        else hash.emplace();
        if (g0 < first) hash_from_file(g0, first);
        const std::uint64_t in0 = std::max(g0, first), in1 = std::min(g1, end);
        const std::uint64_t at0 = stored_offset(in0);
        hash->update(blocks + (at0 - base), stored_offset(in1) - at0);
        if (g1 > end) hash_from_file(end, g1);
        if (hash->digest() != c.group_hashes[g])
            throw Error(Errc::checksum, path_ + ": checksum mismatch in blocks " + std::to_string(g0) + ".." +
                                            std::to_string(g1 - 1) + " (group " + std::to_string(g) +
                                            "): the file is corrupted");
        word.fetch_or(bit, std::memory_order_release);
    }
}

void FftFile::shrank_while_read() const {
    throw Error(Errc::fft_format, path_ + ": unexpected end of file (it shrank while it was read)");
}

// After a read of the mapping: the file still holds `end` bytes. A cut
// inside a page faults only past that page; before it, the mapping reads
// zeros where the file was, which must not pass for damaged blocks.
void FftFile::require_size(std::uint64_t end) const {
    struct stat st {};
    if (::fstat(fd_, &st) != 0) throw Error(Errc::io, path_ + ": cannot stat: " + std::strerror(errno));
    if (std::uint64_t(st.st_size) < end) shrank_while_read();
}

// The first block in the file's mapping, made on the first call; null
// when there is none to make (a container, packed blocks) or mmap fails.
const std::uint8_t* FftFile::mapped_first_block() const {
    if (fd_ < 0 || !mapping_ || fftz_ || header_.packed() || header_.blocks == 0) return nullptr;
    Mapping& m = *mapping_;
    std::call_once(m.once, [&] {
        const std::uint64_t page = std::uint64_t(::sysconf(_SC_PAGESIZE));
        const std::uint64_t start = header_.blocks_offset() / page * page;
        m.skip = std::size_t(header_.blocks_offset() - start);
        m.length = std::size_t(std::uint64_t{header_.blocks} * header_.block_bytes() + m.skip);
        void* a = ::mmap(nullptr, m.length, PROT_READ, MAP_SHARED, fd_, off_t(start));
        if (a != MAP_FAILED) m.address = a;
    });
    return m.address ? static_cast<const std::uint8_t*>(m.address) + m.skip : nullptr;
}

bool FftFile::read_blocks_mapped(std::span<const BlockSpan> spans, std::uint8_t* out) const {
    std::uint64_t end = 0;  // of the spans so far
    for (const BlockSpan& s : spans) {
        require_block_range(s.first, s.count);
        if (s.first < end) throw Error(Errc::invalid_argument, path_ + ": block ranges not ascending");
        end = s.first + s.count;
    }
    const std::uint8_t* blocks = mapped_first_block();
    if (!blocks) return false;
    const std::uint64_t bb = header_.block_bytes();
    thread_local std::vector<detail::MappedCopy> copies;
    copies.clear();
    std::uint8_t* at = out;
    for (const BlockSpan& s : spans) copies.push_back({blocks + s.first * bb, at, s.count * bb}), at += s.count * bb;
    if (!detail::copy_from_mapping(copies)) shrank_while_read();
    require_size(header_.blocks_offset() + end * bb);
    // The spans ascend: a span's fiber is a few fibers past the last one's
    // (a short walk), else searched for.
    const std::uint64_t fibers = fiber_first_block_.size();
    auto fiber_from = [&](std::uint64_t f, std::uint64_t block) {
        for (int step = 0; step < 16; ++step, ++f)
            if (f + 1 >= fibers || fiber_first_block_[f + 1] > block) return f;
        return fiber_of_block(block);
    };
    std::uint64_t fiber = 0;
    at = out;
    for (const BlockSpan& s : spans) {
        if (s.count == 0) continue;
        fiber = fiber_from(fiber, s.first);
        check_block_structure(s.first, s.count, at, fiber);
        if (verifies_checksums()) verify_block_groups(s.first, s.count, at);
        at += s.count * bb;
    }
    return true;
}

std::vector<std::uint8_t> FftFile::read_blocks(std::uint64_t first, std::uint64_t count) const {
    std::vector<std::uint8_t> out(count * header_.block_bytes());
    read_blocks(first, count, out.data());
    return out;
}

}  // namespace fiblet
