// fiblet — integrity checksums of .fft files (formats/fft-checksum.md).
//
// A "CSUM" chunk in the fiblet trailer (which readers of the original format
// never look at) holds XXH64 hashes of the header, of the fiber LUT, of the
// trailer chunks before it, and of every group of `group_blocks` consecutive
// blocks. Per-group hashes let a reader verify exactly the blocks it reads:
// FftFile checks the header and LUT when it opens a file and each block
// group as read_blocks() reads it, so silent corruption (a flipped bit in a
// direction byte) is reported as Error{checksum} instead of decoding into
// wrong fibers. Files without the chunk (the official encoder's) still read.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "fiblet/fft_format.hpp"

namespace fiblet {

inline constexpr std::array<char, 4> kChecksumTag = {'C', 'S', 'U', 'M'};
inline constexpr std::uint32_t kChecksumXxh64 = 1;               // the only algorithm so far
inline constexpr std::uint32_t kDefaultChecksumGroupBlocks = 1024;  // 76 KiB of 76-byte blocks per hash
inline constexpr std::size_t kChecksumFixedBytes = 32;           // payload before the group hashes

// XXH64 (seed 0) of a byte range.
std::uint64_t xxh64(const void* data, std::size_t size);

// Incremental XXH64 (seed 0): the same value as xxh64() of all the bytes given.
class Xxh64Stream {
public:
    Xxh64Stream();
    ~Xxh64Stream();
    Xxh64Stream(const Xxh64Stream&) = delete;
    Xxh64Stream& operator=(const Xxh64Stream&) = delete;
    void update(const void* data, std::size_t size);
    std::uint64_t digest() const;
    void reset();

private:
    alignas(8) std::array<unsigned char, 96> state_;  // XXH64_state_t, kept opaque here
};

// The parsed CSUM chunk.
struct FftChecksums {
    std::uint32_t algorithm = kChecksumXxh64;
    std::uint32_t group_blocks = kDefaultChecksumGroupBlocks;
    std::uint64_t header_hash = 0;   // bytes [0, lut offset): fixed header and buffer table
    std::uint64_t lut_hash = 0;      // the fiber LUT
    std::uint64_t trailer_hash = 0;  // the trailer chunks stored before the CSUM chunk
    std::vector<std::uint64_t> group_hashes;  // blocks [g * group_blocks, (g + 1) * group_blocks), as stored

    std::uint64_t group_count(std::uint64_t blocks) const { return (blocks + group_blocks - 1) / group_blocks; }

    // Parses a CSUM payload for a file of `blocks` blocks; throws
    // Error{checksum} (naming `name`) if it is malformed or names an unknown
    // algorithm: without it nothing in the file can be trusted.
    static FftChecksums parse(const TrailerChunk& chunk, std::uint64_t blocks, const std::string& name);
    TrailerChunk serialize() const;
};

// Builds the CSUM chunk while a writer streams a file out: the LUT and the
// blocks in file order (any split), then finish() with the final header
// bytes (headers are often patched at the end) and the trailer chunks that
// will precede the CSUM chunk, which must be the last chunk.
class FftChecksumBuilder {
public:
    explicit FftChecksumBuilder(std::uint32_t block_bytes, std::uint32_t group_blocks = kDefaultChecksumGroupBlocks);
    void add_lut(const void* data, std::size_t bytes);
    void add_blocks(const void* data, std::size_t bytes);
    // One whole block of `bytes` bytes, as stored: version 17's packed blocks
    // differ in size (their groups still count blocks). A writer uses either
    // add_blocks or add_block for a file, not both.
    void add_block(const void* data, std::size_t bytes);
    TrailerChunk finish(std::span<const std::uint8_t> header, const std::vector<TrailerChunk>& chunks_before);

private:
    std::uint32_t block_bytes_;
    FftChecksums sums_;
    Xxh64Stream lut_, group_;
    std::uint64_t group_bytes_ = 0;  // bytes of the current group so far
    std::uint32_t group_block_count_ = 0;  // add_block: blocks of the current group so far
};

class FftFile;

struct VerifyReport {
    bool has_checksum = false;
    bool index_checked = false;  // the BIDX chunk's boxes and counts were checked against the blocks
    std::uint64_t blocks = 0, groups = 0;  // groups: checksummed groups verified
    std::uint64_t points = 0;              // points the blocks hold (= the header's count)
    std::uint64_t bytes_read = 0;
    // Bytes after the last block left unread (VerifyOptions::ignore_trailer).
    std::uint64_t ignored_trailing_bytes = 0;
};

struct VerifyOptions {
    bool ignore_trailer = false;  // check the blocks of a file whose trailer is damaged
};

// Reads a whole .fft file and checks everything a reader relies on: its
// structure, every hash of its CSUM chunk, each block's identity (fiber ID,
// index in the fiber), the header's point count against the blocks', the
// BIDX chunk's counts and boxes against the decoded blocks, and that every
// point decodes to a finite value. Throws Error{fft_format | checksum | io}.
VerifyReport verify_fft_file(const std::string& path, const std::function<void(double)>& progress = {},
                             const VerifyOptions& options = {});

}  // namespace fiblet
