// Internal: random access to the logical .fft bytes of a .fftz container
// (formats/fftz.md). Every size read from the file is checked before it is
// trusted; frames are decompressed on demand as streams, so memory follows
// what a frame really holds, never what the seek table claims: frames up to
// kMaxCachedFrame are decompressed whole (the last one is cached); the LUT
// and larger frames are read through in order without a copy.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "fiblet/fft_format.hpp"
#include "fiblet/fftz_format.hpp"

struct ZSTD_DCtx_s;  // <zstd.h>

namespace fiblet::detail {

inline constexpr std::uint64_t kMaxCachedFrame = 64u << 20;
// Frames up to this size are decompressed in one call straight into their
// buffer (zstd's window is not copied out): their claimed size is allocated
// before their content is seen, a bounded cost. Larger ones are streamed.
inline constexpr std::uint64_t kOneShotFrameBytes = 16u << 20;
inline constexpr std::size_t kLutFrame = 2;  // frames: descriptor, header, LUT, block groups, [trailer]

class FftzReader {
public:
    // True when the file starts with the FFTZ descriptor frame.
    static bool recognizes(const std::uint8_t* first8, std::size_t size);

    // Reads the seek table and the descriptor; throws Error{fft_format}.
    FftzReader(int fd, std::uint64_t file_size, std::string name);
    ~FftzReader();

    std::uint64_t logical_size() const { return logical_size_; }
    const FftzDescriptor& descriptor() const { return descriptor_; }

    // Checks the frames against the parsed header (header, LUT, one frame
    // per group of blocks, trailer) and enables reading blocks.
    void check_layout(const FftHeader& header);

    // Decompresses the LUT frame once, in bounded memory, so that its size is
    // known to be real before a reader allocates for it. Throws
    // Error{checksum} when it holds other than it claims.
    void check_lut_content() const;

    // Logical bytes [offset, offset + size).
    void read(std::uint8_t* out, std::uint64_t size, std::uint64_t offset) const;

private:
    struct Frame {
        std::uint64_t stored_at, stored_size;  // in the file
        std::uint64_t logical_at, logical_size;
    };
    class FrameStream;
    struct FreeDCtx {
        void operator()(ZSTD_DCtx_s* d) const;
    };
    const std::vector<std::uint8_t>& frame_bytes(std::size_t index) const;  // call with mutex_ held
    // Frame `index` (at most kOneShotFrameBytes) decompressed whole into `out`.
    void decompress_whole(std::size_t index, std::vector<std::uint8_t>& out) const;
    [[noreturn]] void damaged_frame(std::size_t index, const std::string& what) const;
    // Bytes [at, at + size) of a large frame, from a stream kept between calls.
    void read_streamed(std::size_t index, std::uint64_t at, std::uint8_t* out, std::uint64_t size) const;

    int fd_;
    std::string name_;
    std::vector<Frame> frames_;
    FftzDescriptor descriptor_;
    std::uint64_t logical_size_ = 0;
    // Block groups: frames [first_group_, first_group_ + groups_), to untranspose.
    std::size_t first_group_ = 0, groups_ = 0;
    unsigned direction_bits_ = 8;
    std::uint32_t block_bytes_ = 0;
    bool layout_checked_ = false;

    mutable std::mutex mutex_;
    mutable std::size_t cached_ = SIZE_MAX;
    mutable std::vector<std::uint8_t> cache_;
    mutable std::vector<std::uint8_t> fields_;  // a transposed group as decompressed (reused: no zeroing, no regrowth)
    mutable std::vector<std::uint8_t> stored_;  // a frame's compressed bytes (decompress_whole)
    mutable std::unique_ptr<ZSTD_DCtx_s, FreeDCtx> dctx_;
    mutable std::unique_ptr<FrameStream> stream_;  // read_streamed()'s, positioned where it stopped
};

}  // namespace fiblet::detail
