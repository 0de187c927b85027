// fiblet — the block index: a bounding box for every block and a bounding
// volume hierarchy over them, so that a query finds the blocks near a region
// without reading (let alone decoding) the others.
//
// On disk it is the optional "BIDX" trailer chunk (formats/fft-index.md),
// in one of two versions a writer chooses (BlockIndexFormat): version 2
// (the default) stores a quantized box per group of up to 8 consecutive
// blocks of a fiber in 28 bits; version 4 stores a box per block on a grid
// of half a block's path, rANS-coded against the previous block's box
// (about 5 bits a block): fewer candidate blocks for a selection, but about
// 5x slower to load. Both add one byte per fiber (two when blocks hold more
// than 255 points): under 1 % of a file. Versions 1 (a box per block, 28
// bits) and 3 (version 4's boxes, range-coded) are still read. Files
// without it (e.g. from the official encoder) get an index of exact
// per-block boxes computed on load by decoding every block once. The hierarchy is never stored: it is
// rebuilt in memory on load.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "fiblet/fft_file.hpp"
#include "fiblet/fft_format.hpp"
#include "fiblet/image_mask.hpp"
#include "fiblet/index_format.hpp"
#include "fiblet/view.hpp"

namespace fiblet {

inline constexpr std::array<char, 4> kBlockIndexTag = {'B', 'I', 'D', 'X'};
// Blocks under one leaf box of the in-memory hierarchy over a version-3 or
// version-4 index (a leaf that meets a region partly has its blocks' own
// boxes tested, all at once).
inline constexpr std::uint32_t kIndexLeafBlocks = 8;

// Accumulates the bounds of blocks as they are written (compress, extract)
// and serializes them as a BIDX chunk of the chosen format: version 2, a
// box per group of 8 consecutive blocks of a fiber (4 bytes a group), or
// version 4, a box per block (kept, 8 bytes a block, until finished,
// then coded with frequencies of their own). Blocks come in file order, a
// fiber at a time; builders filled in parallel on consecutive fibers are
// joined in order with append() (builders of one format).
class IndexBuilder {
public:
    IndexBuilder();  // unusable until assigned from a header-built one
    explicit IndexBuilder(const FftHeader& header, BlockIndexFormat format = kDefaultBlockIndexFormat);
    IndexBuilder(const IndexBuilder&);
    IndexBuilder& operator=(const IndexBuilder&);
    IndexBuilder(IndexBuilder&&) noexcept;
    IndexBuilder& operator=(IndexBuilder&&) noexcept;
    ~IndexBuilder();

    // The decoded points (world mm) of one whole fiber laid out as the
    // encoder does: blocks of points_per_block points, the last one the rest.
    void add_fiber(std::span<const Vec3f> decoded);
    // One block: its decoded points (n xyz triplets, world mm) and whether it
    // ends its fiber.
    void add_block(const float* xyz, std::uint32_t n, bool last_of_fiber);
    void append(const IndexBuilder& later);
    void clear();

    std::uint64_t blocks() const { return blocks_; }
    std::uint64_t fibers() const { return last_points_.size(); }
    BlockIndexFormat format() const;
    // Boxes too large for the grid (groups in version 2, blocks in version
    // 3), stored as "unbounded" (never culled).
    std::uint64_t unbounded_blocks() const;

    // The BIDX chunk, or nullopt when the layout cannot be described: a
    // block other than the last of its fiber holds fewer than
    // points_per_block points (never the case for files fiblet writes).
    std::optional<TrailerChunk> finish() const;

private:
    struct Coder;  // the boxes as the chosen format stores them (index_builder.cpp)
    struct GroupCoder;
    struct BlockCoder;

    FftHeader header_;
    std::unique_ptr<Coder> coder_;
    std::uint64_t blocks_ = 0;
    std::vector<std::uint16_t> last_points_;
    std::uint32_t open_fiber_blocks_ = 0;  // blocks of the fiber being added
    bool layout_ok_ = true;
    float max_sphere_radius_ = 0;
    double max_join_ = 0;     // largest |last point of a block - first point of the next| in a fiber
    Vec3f last_point_{};      // of the last block added
};

namespace detail {
// Eight boxes of the in-memory hierarchy side by side, each side and axis
// an array (index/box_tests.hpp tests them together).
inline constexpr std::size_t kBoxGroupSize = 8;
struct BoxGroup {
    float lo[3][kBoxGroupSize], hi[3][kBoxGroupSize];
};
}  // namespace detail

// The index of one file, in memory: boxes of groups of consecutive blocks
// (a version-2 chunk's groups; one box per block from a version-1 chunk or
// computed exactly; for a version-3 or -4 chunk, groups of kIndexLeafBlocks
// bounding their blocks' own boxes), per-fiber point counts, and a bounding
// volume hierarchy (8-wide, over the groups sorted along a Morton curve) to
// find the blocks that meet a region.
class BlockIndex {
public:
    enum class Source { chunk, decoded };

    // The file's BIDX chunk when it has one, else computed by decoding every
    // block. Throws Error{fft_format} on a malformed chunk.
    static BlockIndex load(const FftFile& file);
    // Always computed by decoding (exact boxes), ignoring any chunk.
    static BlockIndex compute(const FftFile& file);
    // The version of the file's BIDX chunk (its first field), without
    // loading it; nullopt when the file has none. Throws Error{fft_format}
    // on a chunk too short to hold it.
    static std::optional<std::uint32_t> stored_version(const FftFile& file);

    Source source() const { return source_; }
    // The stored chunk's version (1 to 4; BlockIndexFormat's values for
    // those fiblet writes); 0 when computed.
    std::uint32_t chunk_version() const { return chunk_version_; }
    std::uint64_t blocks() const { return blocks_; }
    // Leaf boxes of the hierarchy: groups of consecutive blocks of a fiber
    // (one block each when computed).
    std::uint64_t groups() const { return order_.size(); }
    std::uint64_t fibers() const { return fiber_points_.size(); }
    std::uint64_t fiber_points(std::uint64_t fiber) const { return fiber_points_[fiber]; }
    // Bounds of every point a block decodes to: its own box, or its group's
    // (version 2) (conservative; escaped ones are unbounded).
    Aabb block_box(std::uint64_t block) const;
    // A box that holds the block's first point, the centre of its view
    // sphere: with a box per block (versions 3 and 4) its own box narrowed
    // to the previous block's of its fiber grown by max_join() (the fiber
    // moves on: the two touch only where one ends and the next begins);
    // block_box otherwise.
    Aabb first_point_box(std::uint64_t block) const;
    // A box around every point of the file (the union of its boxes);
    // nullopt when some box is unbounded or there is no block.
    std::optional<Aabb> bounds() const;
    // Every block's view sphere (view.hpp) has a radius at most this.
    float max_sphere_radius() const { return max_sphere_radius_; }
    // A block's last point lies at most this far (mm) from the next block's
    // first point of its fiber; negative when unknown (version-1 chunks,
    // computed indexes).
    float max_join() const { return max_join_; }

    // Blocks whose box may meet a sphere / a box / the frustum grown by
    // `margin`: a bitmap of blocks() bits, ORed into `bits` (resized as
    // needed). Conservative: a block with a point in the region is always
    // set. When `inside` is given, the blocks whose box lies wholly inside
    // the region (so every point does) are also set there.
    void blocks_near_sphere(Vec3f center, float radius, std::vector<std::uint64_t>& bits,
                            std::vector<std::uint64_t>* inside = nullptr) const;
    void blocks_near_box(const Aabb& box, std::vector<std::uint64_t>& bits,
                         std::vector<std::uint64_t>* inside = nullptr) const;
    void blocks_near_mask(const ImageMask& mask, std::vector<std::uint64_t>& bits,
                          std::vector<std::uint64_t>* inside = nullptr) const;
    void blocks_near_frustum(const Frustum& frustum, float margin, std::vector<std::uint64_t>& bits) const;
    // Blocks whose first point may lie within `margin` of the frustum
    // (first_point_box grown by margin meets it): with margin at least
    // max_sphere_radius(), every block whose view sphere meets the frustum.
    void blocks_starting_near_frustum(const Frustum& frustum, float margin, std::vector<std::uint64_t>& bits) const;

private:
    BlockIndex() = default;
    void set_blocks(std::vector<Aabb> boxes);  // one group per block; sorts and builds the hierarchy
    void set_groups(const std::vector<Aabb>& boxes);  // of group_first_'s groups; sorts and builds it
    Aabb cells_union(const std::uint64_t* cells, std::size_t n) const;  // of n packed grid boxes
    void sort_block_cells(const std::vector<std::uint64_t>& cells);  // file order -> block_cells_
    std::size_t group_of(std::uint64_t block) const;  // the group holding a block
    std::size_t cell_of(std::uint64_t block) const;   // a block's place in block_cells_
    // first_point_box's cells in quarter cells, as block_cells_ (made once).
    const std::vector<std::uint64_t>& first_point_cells() const;
    template <class BoxOf>
    void build(std::vector<std::uint64_t>& keyed, const BoxOf& box_of);  // (Morton key << 32 | group)
    // Which boxes of its blocks a leaf the region meets partly tests.
    enum class LeafBoxes { own, first_point };
    // Sets the blocks `test` (index/box_tests.hpp) finds near its region.
    template <LeafBoxes kLeafBoxes, class Test>
    void collect(const Test& test, std::vector<std::uint64_t>& bits, std::vector<std::uint64_t>* inside) const;

    Source source_ = Source::decoded;
    std::uint32_t chunk_version_ = 0;
    std::vector<std::uint64_t> fiber_points_;
    float max_sphere_radius_ = 0;
    float max_join_ = -1;
    std::uint64_t blocks_ = 0;
    std::vector<std::uint32_t> group_first_;     // group -> its first block; one more: blocks_
    std::vector<std::uint32_t> order_;           // Morton position -> group
    struct BlockRange {
        std::uint32_t first, end;
    };
    std::vector<BlockRange> leaf_blocks_;        // Morton position -> its group's blocks (no lookup through order_)
    std::vector<std::uint32_t> rank_;            // group -> Morton position
    // The hierarchy, 8-wide: boxes_[k][j] holds the boxes of the children of
    // node j of level k (k = 0: leaves' parents, whose children are the
    // leaves in Morton order); the top level has the root alone.
    std::vector<std::vector<detail::BoxGroup>> boxes_;
    Aabb root_{};
    // Versions 3 and 4: each block's grid box, packed in 64 bits (the
    // library's index/index_grid.hpp), leaf after leaf in Morton order;
    // boxes in mm are origin + cell number * cell.
    std::vector<std::uint64_t> block_cells_;
    struct FirstPointCells;
    std::shared_ptr<FirstPointCells> first_points_;  // first_point_cells(), shared by copies
    std::vector<std::uint32_t> leaf_first_cell_;  // Morton position -> its first block's cells; one more: blocks_
    Vec3f cells_origin_{};
    float cell_mm_ = 0;
};

}  // namespace fiblet
