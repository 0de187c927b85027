// fiblet — the .fft (Fiblets, version 2) file layout.
//
// See formats/fft.md for the full specification. Everything is little-endian
// and unpadded:
//   header   u8 version=2, u64 nbFibers, u64 nbPoints, u32 nbBlocks,
//            u32 pointsPerBlock, f32 scaling, f32x3 offset, f32 ratio,
//            f32 step (normalized units), f32 maxError (mm), f32 meanError (mm),
//            u8 nbSSBOs, u64 x nbSSBOs (cumulative block count per GPU buffer)
//   LUT      per fiber u32 x, u32 y (x = buffer << 16 | blocks, y = first block
//            of the fiber inside its buffer)
//   blocks   nbBlocks x blockSize bytes (76 for 60 points)
//
// The 16-bit variants (formats/fft16.md) have the same header with version
// = 16 or 17, so readers of version 2 reject them cleanly; their blocks hold
// unorm24 anchors and wide direction codes. Version 16 stores fixed-size
// blocks; version 17 stores packed blocks (15-bit codes, no padding, no
// per-block id or flags) that FftFile expands, on reading, to the in-memory
// block layout of version 16 (BlockView16), so every consumer of blocks
// sees one 16-bit layout.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "fiblet/geometry.hpp"

namespace fiblet {

inline constexpr std::uint8_t kFftVersion = 2;
inline constexpr std::uint8_t kFft16Version = 16;        // 16-bit directions, fixed-size blocks (formats/fft16.md)
inline constexpr std::uint8_t kFft16PackedVersion = 17;  // 15-bit directions, packed blocks (formats/fft16.md)
inline constexpr std::uint32_t kDefaultPointsPerBlock = 60;
inline constexpr std::uint32_t kMaxPointsPerBlock = 63;  // 6-bit count in the flags byte
inline constexpr std::size_t kFftFixedHeaderBytes = 1 + 8 + 8 + 4 + 4 + 4 * 8 + 1;  // up to the SSBO table

// Byte offsets inside a block.
inline constexpr std::size_t kBlockAnchorBytes = 12;  // two points, six unorm16
inline constexpr std::size_t kBlockFiberIdOffset = 12;
inline constexpr std::size_t kBlockFlagsOffset = 16;
inline constexpr std::size_t kBlockIndexOffset = 17;
inline constexpr std::size_t kBlockDirectionsOffset = 18;

inline constexpr std::uint8_t kFlagNotFirst = 0x80;
inline constexpr std::uint8_t kFlagNotLast = 0x40;
inline constexpr std::uint8_t kFlagCountMask = 0x3f;

// Block size for a number of points: points + 16 rounded up to 4 bytes.
constexpr std::uint32_t fft_block_bytes(std::uint32_t points_per_block) {
    return (points_per_block + 16 + 3) / 4 * 4;
}

// 16-bit blocks (formats/fft16.md): six unorm24 anchor coordinates (18
// bytes), u32 fiber id, u16 flags/count, then one u16 code per further
// point; everything little-endian.
inline constexpr std::uint32_t kDefaultPointsPerBlock16 = 126;
inline constexpr std::uint32_t kMaxPointsPerBlock16 = 16383;  // 14-bit count
inline constexpr std::size_t kBlock16FiberIdOffset = 18;
inline constexpr std::size_t kBlock16FlagsOffset = 22;
inline constexpr std::size_t kBlock16DirectionsOffset = 24;
inline constexpr std::uint16_t kFlag16NotFirst = 0x8000;
inline constexpr std::uint16_t kFlag16NotLast = 0x4000;
inline constexpr std::uint16_t kFlag16CountMask = 0x3fff;

// 24 header bytes + 2 per direction, rounded up to 4 bytes.
constexpr std::uint32_t fft16_block_bytes(std::uint32_t points_per_block) {
    return (24 + 2 * (points_per_block - 2) + 3) / 4 * 4;
}

// Packed blocks of version 17 on disk (formats/fft16.md): the 18 anchor
// bytes, then n - 2 codes of 15 bits (levels 181 x 181) as one bit stream,
// least significant bit first, zero bits up to the next byte. Every block of
// a fiber holds pointsPerBlock points but its last; blocks follow each other
// with no gap, so a block's offset follows from the fiber LUT.
inline constexpr std::uint32_t kDefaultPointsPerBlock16Packed = 254;
inline constexpr std::size_t kPacked16AnchorBytes = 18;
inline constexpr unsigned kPacked16CodeBits = 15;
constexpr std::uint32_t packed16_block_bytes(std::uint32_t points) {
    return std::uint32_t(kPacked16AnchorBytes) + (points > 2 ? (kPacked16CodeBits * (points - 2) + 7) / 8 : 0);
}

// Largest number of blocks one GPU buffer holds (2^31 bytes / block size).
constexpr std::uint64_t fft_max_blocks_per_buffer(std::uint32_t block_bytes) {
    return (std::uint64_t{1} << 31) / block_bytes;
}

struct FftHeader {
    std::uint8_t version = kFftVersion;
    std::uint64_t fibers = 0;
    std::uint64_t points = 0;
    std::uint32_t blocks = 0;
    std::uint32_t points_per_block = kDefaultPointsPerBlock;
    float scaling = 1;                 // mm per normalized unit
    std::array<float, 3> offset{};     // mm, added before scaling
    float ratio = 1;                   // spherical-cap parameter of the direction code
    float step = 0;                    // step length in normalized units
    float max_error_mm = 0;
    float mean_error_mm = 0;
    std::vector<std::uint64_t> buffer_ends;  // cumulative block count at the end of each buffer
    // Version 17: bytes of the packed blocks on disk, known from the fiber
    // LUT (FftFile sets it after reading the LUT, the encoder after encoding).
    std::uint64_t packed_block_bytes = 0;

    // 8 for version 2, 16 for the 16-bit variants.
    unsigned direction_bits() const { return version == kFft16Version || packed() ? 16 : 8; }
    // Version 17: packed blocks on disk, expanded on reading.
    bool packed() const { return version == kFft16PackedVersion; }
    // Levels per diagonal axis of the direction code.
    unsigned code_levels() const { return packed() ? 181 : version == kFft16Version ? 256 : 16; }
    std::uint32_t max_points_per_block() const {
        return direction_bits() == 16 ? kMaxPointsPerBlock16 : kMaxPointsPerBlock;
    }
    // Bytes of a block in memory (for version 17: expanded, as version 16).
    std::uint32_t block_bytes() const {
        return direction_bits() == 16 ? fft16_block_bytes(points_per_block) : fft_block_bytes(points_per_block);
    }
    float step_mm() const { return step * scaling; }
    // Bytes before the fiber LUT / before the first block.
    std::uint64_t lut_offset() const { return kFftFixedHeaderBytes + 8 * buffer_ends.size(); }
    std::uint64_t blocks_offset() const { return lut_offset() + 8 * fibers; }
    std::uint64_t file_bytes() const {
        return blocks_offset() + (packed() ? packed_block_bytes : std::uint64_t{blocks} * block_bytes());
    }

    // Normalized <-> world coordinates.
    Vec3f to_world(float nx, float ny, float nz) const {
        return {(nx - 0.5f) * scaling - offset[0], (ny - 0.5f) * scaling - offset[1],
                (nz - 0.5f) * scaling - offset[2]};
    }
};

struct FiberLutEntry {
    std::uint32_t x = 0;  // buffer index << 16 | number of blocks
    std::uint32_t y = 0;  // first block inside the buffer

    std::uint32_t buffer() const { return x >> 16; }
    std::uint32_t block_count() const { return x & 0xffffu; }
};

// Serializes the header (fixed part + buffer table) into bytes.
std::vector<std::uint8_t> serialize_fft_header(const FftHeader& h);

// fiblet extension trailer (formats/fft.md, "Trailer"): optional chunks after
// the last block, which readers of the original format never look at.
// Layout: chunks { char tag[4]; u32 flags = 0; u64 size; u8 payload[size] },
// then a 16-byte footer { u64 offset of the first chunk; "FIBLETX1" }.
inline constexpr char kTrailerMagic[8] = {'F', 'I', 'B', 'L', 'E', 'T', 'X', '1'};
inline constexpr std::size_t kTrailerFooterBytes = 16;
struct TrailerChunk {
    std::array<char, 4> tag{};
    std::vector<std::uint8_t> payload;
};
// Appends one chunk (16-byte head, then the payload) to `out`; or its head alone.
void append_trailer_chunk(std::vector<std::uint8_t>& out, const TrailerChunk& chunk);
void append_trailer_chunk_head(std::vector<std::uint8_t>& out, const TrailerChunk& chunk);
// Serializes chunks + footer; `trailer_offset` is where the first chunk starts.
std::vector<std::uint8_t> serialize_trailer(const std::vector<TrailerChunk>& chunks, std::uint64_t trailer_offset);

// "PROP" chunk: the source .tck header properties, in order, each as two
// strings (key, value), each string a u32 byte count then its bytes.
inline constexpr std::array<char, 4> kPropertiesTag = {'P', 'R', 'O', 'P'};
// "RSMP" chunk, present when the encoder resampled variable-step input to
// the fixed step: payload f64 step in mm. Tells a comparison to resample the
// reference the same way.
inline constexpr std::array<char, 4> kResampledTag = {'R', 'S', 'M', 'P'};
TrailerChunk make_properties_chunk(const std::vector<std::pair<std::string, std::string>>& properties);

// Read-only view of one block's fields.
struct BlockView {
    const std::uint8_t* bytes;

    std::uint8_t flags() const { return bytes[kBlockFlagsOffset]; }
    std::uint32_t point_count() const { return flags() & kFlagCountMask; }
    bool is_first() const { return !(flags() & kFlagNotFirst); }
    bool is_last() const { return !(flags() & kFlagNotLast); }
    std::uint32_t index_in_fiber() const { return bytes[kBlockIndexOffset]; }
    std::uint32_t fiber_id() const {
        return std::uint32_t{bytes[12]} << 24 | std::uint32_t{bytes[13]} << 16 | std::uint32_t{bytes[14]} << 8 |
               bytes[15];
    }
    // Anchor k (0 or 1) in normalized coordinates, as six unorm16 values.
    // Inline: selections read the anchors of every candidate block.
    inline std::array<std::uint16_t, 6> anchor_words() const;
    inline std::array<float, 6> anchors_normalized() const;
    const std::uint8_t* directions() const { return bytes + kBlockDirectionsOffset; }
};

// unorm16 as GLSL packUnorm2x16 defines it: round(clamp(v, 0, 1) * 65535).
std::uint16_t pack_unorm16(float v);
inline float unpack_unorm16(std::uint16_t q) { return float(q) / 65535.0f; }

std::array<std::uint16_t, 6> BlockView::anchor_words() const {
    // Word k holds the pair (a, b) as a | b << 16, stored most-significant byte first.
    std::array<std::uint16_t, 6> q{};
    for (int k = 0; k < 3; ++k) {
        const std::uint8_t* w = bytes + 4 * k;
        q[2 * k] = static_cast<std::uint16_t>(w[2] << 8 | w[3]);
        q[2 * k + 1] = static_cast<std::uint16_t>(w[0] << 8 | w[1]);
    }
    return q;
}

std::array<float, 6> BlockView::anchors_normalized() const {
    const auto q = anchor_words();
    std::array<float, 6> v{};
    for (int i = 0; i < 6; ++i) v[i] = unpack_unorm16(q[i]);
    return v;
}

// unorm24 (16-bit blocks): round(clamp(v, 0, 1) * (2^24 - 1)); every value
// is exact in a float, so decoding rounds once.
inline constexpr std::uint32_t kUnorm24Max = (1u << 24) - 1;
inline float unpack_unorm24(std::uint32_t q) { return float(q) / float(kUnorm24Max); }

// Read-only view of one 16-bit block's fields.
struct BlockView16 {
    const std::uint8_t* bytes;

    std::uint16_t flags() const { return std::uint16_t(bytes[kBlock16FlagsOffset] | bytes[kBlock16FlagsOffset + 1] << 8); }
    std::uint32_t point_count() const { return flags() & kFlag16CountMask; }
    bool is_first() const { return !(flags() & kFlag16NotFirst); }
    bool is_last() const { return !(flags() & kFlag16NotLast); }
    std::uint32_t fiber_id() const {
        const std::uint8_t* p = bytes + kBlock16FiberIdOffset;
        return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
    }
    // The six anchor coordinates (x0 y0 z0 x1 y1 z1), unorm24.
    std::uint32_t anchor_word(int i) const {
        const std::uint8_t* p = bytes + 3 * i;
        return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16;
    }
    std::array<float, 6> anchors_normalized() const {
        std::array<float, 6> v{};
        for (int i = 0; i < 6; ++i) v[i] = unpack_unorm24(anchor_word(i));
        return v;
    }
    std::uint16_t code(std::uint32_t k) const {  // direction of point k + 2
        const std::uint8_t* p = bytes + kBlock16DirectionsOffset + 2 * k;
        return std::uint16_t(p[0] | p[1] << 8);
    }
};

// Point count, first/last flags and identity (fiber ID, and for 8-bit
// blocks the index within the fiber modulo 256) of a block of either kind
// (8-bit version-2 blocks or 16-bit blocks), for code that only walks the
// structure.
struct BlockFlags {
    std::uint32_t point_count;
    bool first, last;
    std::uint32_t fiber_id;
    std::optional<std::uint32_t> index_in_fiber;  // 16-bit blocks have none
};
inline BlockFlags block_flags(const FftHeader& h, const std::uint8_t* block) {
    if (h.direction_bits() == 16) {
        const BlockView16 v{block};
        return {v.point_count(), v.is_first(), v.is_last(), v.fiber_id(), std::nullopt};
    }
    const BlockView v{block};
    return {v.point_count(), v.is_first(), v.is_last(), v.fiber_id(), v.index_in_fiber()};
}
// The two anchors (x0 y0 z0 x1 y1 z1, normalized) of a block of either kind.
inline std::array<float, 6> block_anchors_normalized(const FftHeader& h, const std::uint8_t* block) {
    return h.direction_bits() == 16 ? BlockView16{block}.anchors_normalized() : BlockView{block}.anchors_normalized();
}

}  // namespace fiblet
