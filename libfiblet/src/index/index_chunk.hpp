// Internal: the BIDX chunk's layout (formats/fft-index.md): the grid that
// quantizes boxes, the fields of the chunk, and parsing with validation.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "fiblet/fft_file.hpp"
#include "fiblet/fft_format.hpp"
#include "fiblet/view.hpp"
#include "index/index_grid.hpp"

namespace fiblet::detail {

// Versions 4 and 3 bound every block, their boxes coded against the
// previous box (4: rANS, box_rans.hpp, written; 3: a binary range coder,
// box_stream.hpp, still read); version 2 bounds groups of consecutive blocks
// of a fiber, a fixed-width code each; version 1 (a box per block, fixed
// width) is still read.
inline constexpr std::uint32_t kIndexChunkVersion = 4;
inline constexpr std::uint32_t kIndexChunkV3Version = 3;
inline constexpr std::uint32_t kIndexChunkV2Version = 2;
inline constexpr unsigned kIndexV2BitsPerBox = 28;  // bits per group box code
inline constexpr std::uint32_t kIndexV2GroupBlocks = 8;
inline constexpr std::size_t kIndexChunkHeaderBytes = 64, kIndexChunkV2HeaderBytes = 72,
                             kIndexChunkV1HeaderBytes = 56;

// Decodes codes into boxes (unbounded ones span the float range) with per-axis
// tables: no integer division per block.
class IndexBoxDecoder {
public:
    explicit IndexBoxDecoder(const IndexGrid& g);
    bool unbounded(std::uint32_t code) const { return code == unbounded_; }
    Aabb box(std::uint32_t code) const {
        if (unbounded(code)) return unbounded_box();
        std::uint32_t c[3];
        split(code, c);
        return {{lo_[0][c[0]], lo_[1][c[1]], lo_[2][c[2]]}, {hi_[0][c[0]], hi_[1][c[1]], hi_[2][c[2]]}};
    }
    // Twice the box centre in cells, per axis (for ordering boxes).
    void centre2(std::uint32_t code, std::uint32_t out[3]) const {
        std::uint32_t c[3];
        split(code, c);
        for (int a = 0; a < 3; ++a) out[a] = 2 * (c[a] / e_) + c[a] % e_;
    }
    std::uint32_t max_centre2() const { return 2 * (levels_ / e_) + e_; }

private:
    void split(std::uint32_t code, std::uint32_t c[3]) const {
        // Exact: a quotient of integers below 2^32 by one below 2^16 is never
        // rounded across an integer in double precision.
        const auto q = std::uint32_t(double(code) / double(levels_));
        const auto z = std::uint32_t(double(q) / double(levels_));
        c[0] = code - q * levels_, c[1] = q - z * levels_, c[2] = z;
    }
    std::uint32_t levels_, e_, unbounded_;
    std::vector<float> lo_[3], hi_[3];
};

// Bytes per fiber of the last-block point counts.
inline unsigned index_count_bytes(const FftHeader& h) { return h.points_per_block <= 255 ? 1 : 2; }

// Groups of a fiber of `blocks` blocks: runs of group_blocks from its first
// block, the last one the rest.
inline std::uint64_t index_groups_of_fiber(std::uint64_t blocks, std::uint32_t group_blocks) {
    return (blocks + group_blocks - 1) / group_blocks;
}

struct IndexChunk {
    std::uint32_t version = kIndexChunkVersion;
    IndexGrid grid;
    std::uint32_t group_blocks = 1;  // 1 in versions 1 and 3
    std::uint64_t fibers = 0, blocks = 0, groups = 0;
    float max_sphere_radius = 0;
    // Largest distance from a block's last point to the next block's first
    // (same fiber), mm; negative: unknown (version 1).
    float max_join = -1;
    std::vector<std::uint16_t> last_block_points;  // per fiber (stored in 1 byte, or 2 beyond 255 points a block)
    std::vector<std::uint32_t> codes;             // per group (versions 1 and 2)
    std::size_t box_stream_offset = 0, box_stream_bytes = 0;  // in the payload (versions 3 and 4)
};

// A version-4 chunk: its fields, the per-fiber counts and the coded boxes.
std::vector<std::uint8_t> serialize_index_chunk(const IndexChunk& c, const FftHeader& h,
                                                const std::vector<std::uint8_t>& box_stream);
// A version-2 chunk: its fields, the per-fiber counts and c.codes.
std::vector<std::uint8_t> serialize_index_chunk_v2(const IndexChunk& c, const FftHeader& h);
// Parses and validates a chunk against its file's header (counts, levels,
// sizes). Throws Error{fft_format} naming `file`. What needs the fiber LUT
// (the group count, point totals, version 3's boxes) is checked by its users.
IndexChunk parse_index_chunk(const std::vector<std::uint8_t>& payload, const FftHeader& h, const std::string& file);
// Versions 3 and 4: every block's grid box (pack_cells, or
// kUnboundedCells), decoded with the file's fibers. Throws
// Error{fft_format} on a malformed stream.
std::vector<std::uint64_t> index_block_cells(const IndexChunk& c, const std::vector<std::uint8_t>& payload,
                                             const FftFile& file);
// The same in mm (unbounded ones span the float range).
std::vector<Aabb> index_block_boxes(const IndexChunk& c, const std::vector<std::uint8_t>& payload,
                                    const FftFile& file);

}  // namespace fiblet::detail
