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
#include "index/box_stream.hpp"

namespace fiblet::detail {

// Version 3 (written on request) bounds every block, its boxes range-coded
// (box_stream.hpp); version 2 (written by default) bounds groups of
// consecutive blocks of a fiber, a fixed-width code each; version 1 (a box
// per block, fixed width) is still read.
inline constexpr std::uint32_t kIndexChunkVersion = 3;
inline constexpr std::uint32_t kIndexChunkV2Version = 2;
inline constexpr unsigned kIndexV2BitsPerBox = 28;  // bits per group box code
inline constexpr std::uint32_t kIndexV2GroupBlocks = 8;
inline constexpr std::size_t kIndexChunkHeaderBytes = 64, kIndexChunkV2HeaderBytes = 72,
                             kIndexChunkV1HeaderBytes = 56;

// Boxes are stored on a cubic grid: on each axis a box is [origin + i*cell,
// origin + (i+e)*cell] with i < min_levels and e < extent_levels. Versions
// 1 and 2 store a box as one code: the three axis codes i*extent_levels + e
// in mixed radix (x fastest), the all-ones code of `bits` bits meaning
// "unbounded" (a group that does not fit the grid). Version 3 codes i and e
// themselves (GridBox).
struct IndexGrid {
    Vec3f origin{};
    float cell = 1;
    std::uint32_t min_levels = 1, extent_levels = 1;
    unsigned bits = 28;  // versions 1 and 2

    std::uint32_t axis_levels() const { return min_levels * extent_levels; }
    std::uint32_t unbounded_code() const { return bits >= 32 ? 0xffffffffu : (1u << bits) - 1; }

    // The version-3 grid of a file: covers the normalized cube (with a
    // margin) in cells of half a block's path.
    static IndexGrid for_blocks(const FftHeader& h);
    // The version-2 grid of a file: covers the normalized cube (with a
    // margin) and makes the cells as small as `bits` allow for groups of
    // `group_blocks` blocks, up to group_blocks * points_per_block steps across.
    static IndexGrid for_groups(const FftHeader& h, unsigned bits, std::uint32_t group_blocks);
    // Conservative grid box of a box (its bounds contain it, with a small
    // slack for float rounding), or nullopt when it does not fit the grid.
    std::optional<GridBox> quantize(const Aabb& box) const;
    Aabb bounds(const GridBox& b) const;
    std::optional<std::pair<std::uint32_t, std::uint32_t>> axis_cells(float o, float lo, float hi) const;
    // Version 2: the conservative code of a box (the decoded box contains
    // it, with the same slack), or unbounded_code().
    std::uint32_t encode(const Aabb& box) const;
};

// A box at least this large is unbounded (is_unbounded()).
inline constexpr float kUnboundedExtentMm = 1e30f;
// Every finite point: a block may lie anywhere in the float range.
inline Aabb unbounded_box() {
    const float m = std::numeric_limits<float>::max();
    return {{-m, -m, -m}, {m, m, m}};
}

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
    std::size_t box_stream_offset = 0, box_stream_bytes = 0;  // in the payload (version 3)
};

// A version-3 chunk: its fields, the per-fiber counts and the coded boxes.
std::vector<std::uint8_t> serialize_index_chunk(const IndexChunk& c, const FftHeader& h,
                                                const std::vector<std::uint8_t>& box_stream);
// A version-2 chunk: its fields, the per-fiber counts and c.codes.
std::vector<std::uint8_t> serialize_index_chunk_v2(const IndexChunk& c, const FftHeader& h);
// Parses and validates a chunk against its file's header (counts, levels,
// sizes). Throws Error{fft_format} naming `file`. What needs the fiber LUT
// (the group count, point totals, version 3's boxes) is checked by its users.
IndexChunk parse_index_chunk(const std::vector<std::uint8_t>& payload, const FftHeader& h, const std::string& file);
// Version 3: every block's box (unbounded ones span +-1e30 mm), decoded
// with the file's fibers. Throws Error{fft_format} on a malformed stream.
std::vector<Aabb> index_block_boxes(const IndexChunk& c, const std::vector<std::uint8_t>& payload,
                                    const FftFile& file);

}  // namespace fiblet::detail
