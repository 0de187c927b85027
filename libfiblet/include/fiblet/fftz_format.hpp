// fiblet — the seekable zstd container of .fft files (.fftz).
//
// See formats/fftz.md. A .fftz is a zstd stream in the zstd seekable format
// whose frames hold, in order, the bytes of a .fft file (version 2 or 16):
//   frame 0   skippable frame (magic 0x184D2A50): the FFTZ descriptor
//   frame 1   the .fft header (a zstd frame of one raw block)
//   frame 2   the fiber LUT
//   frames    groups of `group_blocks` blocks each, independently compressed
//   [frame]   the .fft trailer, when the file has one
//   seek table (skippable frame 0x184D2A5E, zstd seekable format)
// A group is stored as is (layout 0), or field by field (layout 1, see
// transpose_block_group), which compresses better. With layout 0,
// `zstd -d x.fftz` gives back the .fft file byte for byte.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace fiblet {

inline constexpr std::uint32_t kZstdSkippableMagic = 0x184D2A50;      // + 0..15
inline constexpr std::uint32_t kZstdSeekTableMagic = 0x184D2A5E;      // skippable frame of the seek table
inline constexpr std::uint32_t kZstdSeekableFooterMagic = 0x8F92EAB1;  // last 4 bytes of the stream
inline constexpr char kFftzMagic[4] = {'F', 'F', 'T', 'Z'};
inline constexpr std::uint8_t kFftzVersion = 1;
inline constexpr std::size_t kFftzDescriptorBytes = 16;  // payload of frame 0

enum class FftzLayout : std::uint8_t {
    plain = 0,       // block groups as in the .fft
    transposed = 1,  // block groups field by field (transpose_block_group)
};

// Payload of the descriptor frame: "FFTZ", u8 version = 1, u8 layout,
// u16 reserved = 0, u32 blocks per group, u32 reserved = 0 (little-endian).
struct FftzDescriptor {
    FftzLayout layout = FftzLayout::transposed;
    std::uint32_t group_blocks = 4096;
};

// Field-by-field form of `count` blocks of one .fft (direction_bits 8 or 16,
// `block_bytes` each), and its inverse; both sizes are count * block_bytes.
//   1. the six anchor values of every block, anchor 1 replaced by its
//      difference to anchor 0 (modulo 2^16 or 2^24): value by value, byte
//      by byte from the most significant, one byte per block;
//   2. the remaining block header bytes (fiber id, flags, index / count):
//      byte position by byte position, one byte per block;
//   3. the direction codes: 8-bit codes block after block as stored;
//      16-bit codes as two planes, all high bytes then all low bytes.
std::vector<std::uint8_t> transpose_block_group(std::span<const std::uint8_t> blocks, unsigned direction_bits,
                                                std::uint32_t block_bytes);
std::vector<std::uint8_t> untranspose_block_group(std::span<const std::uint8_t> fields, unsigned direction_bits,
                                                  std::uint32_t block_bytes);
// The same into `blocks` (as many bytes as `fields`; throws
// Error{invalid_argument} otherwise).
void untranspose_block_group(std::span<const std::uint8_t> fields, unsigned direction_bits, std::uint32_t block_bytes,
                             std::span<std::uint8_t> blocks);

}  // namespace fiblet
