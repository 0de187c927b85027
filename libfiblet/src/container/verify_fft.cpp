// Whole-file verification: structure, every checksum, and everything a
// reader relies on, cross-checked against the blocks themselves.
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "fiblet/block_index.hpp"
#include "fiblet/checksum.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "index/index_chunk.hpp"

namespace fiblet {

namespace {

// Walks the blocks in file order, a fiber at a time, checking what no
// checksum can (a file may have none, or a writer may have been wrong): the
// header's point count, the BIDX chunk's per-fiber counts and boxes, and
// that every decoded point is finite. The chunk is read as parsed (2 bytes a
// fiber, 4 a group of blocks; version 3: 24 bytes a block), not as a
// BlockIndex with its hierarchy.
class BlockCrossCheck {
public:
    // Decoded as every reader decodes them: with the file's kept fiber ends.
    explicit BlockCrossCheck(const FftFile& file) : file_(file), ctx_(file) {
        if (const TrailerChunk* c = file.find_chunk(kBlockIndexTag)) {
            index_.emplace(detail::parse_index_chunk(c->payload, file.header(), file.path()));
            if (index_->version >= detail::kIndexChunkV3Version)  // a box per block
                block_boxes_ = detail::index_block_boxes(*index_, c->payload, file);
            else
                boxes_.emplace(index_->grid);  // versions 1 and 2: codes
        }
    }
    bool checks_index() const { return index_.has_value(); }

    void add(std::uint64_t first, std::uint64_t count, const std::uint8_t* blocks) {
        const FftHeader& h = file_.header();
        xyz_.resize(3 * count_block_points(ctx_, blocks, count));
        decode_blocks(ctx_, blocks, count, xyz_.data());
        const float* p = xyz_.data();
        for (std::uint64_t b = 0; b < count; ++b) {
            const std::uint32_t n = block_flags(h, blocks + b * h.block_bytes()).point_count;
            next_block();
            check_points(first + b, p, n);
            check_join(first + b, p, n);
            fiber_points_ += n, points_ += n;
            p += 3 * n;
        }
    }

    std::uint64_t finish() {
        const FftHeader& h = file_.header();
        if (started_) end_fiber(), ++fiber_, fiber_points_ = 0;
        for (; fiber_ < h.fibers; ++fiber_, fiber_points_ = 0) check_fiber();  // the fibers after the last block
        if (index_ && group_base_ != index_->groups)
            fail("the BIDX chunk stores " + std::to_string(index_->groups) + " groups, the fibers have " +
                 std::to_string(group_base_));
        if (points_ != h.points)
            fail("the blocks hold " + std::to_string(points_) + " points, the header says " + std::to_string(h.points));
        return points_;
    }

private:
    [[noreturn]] void fail(const std::string& what) const {
        throw Error(Errc::fft_format, file_.path() + ": not a valid .fft file: " + what);
    }

    void check_points(std::uint64_t block, const float* p, std::uint32_t n) const {
        // The block's box is its group's: G blocks at a time from its fiber's
        // first (version 3: G = 1, its own box).
        const std::uint64_t group = index_ ? group_base_ + (block_in_fiber_ - 1) / index_->group_blocks : 0;
        if (index_ && group >= index_->groups)
            fail("the fibers have more groups than the BIDX chunk stores (" + std::to_string(index_->groups) + ")");
        const Aabb box = !index_ ? Aabb{} : boxes_ ? boxes_->box(index_->codes[group]) : block_boxes_[group];
        for (std::uint32_t i = 0; i < n; ++i, p += 3) {
            if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])))
                fail("block " + std::to_string(block) + " decodes to a non-finite point");
            if (index_ && !(p[0] >= box.min.x && p[0] <= box.max.x && p[1] >= box.min.y && p[1] <= box.max.y &&
                            p[2] >= box.min.z && p[2] <= box.max.z))
                fail("block " + std::to_string(block) +
                     " decodes to points outside its box in the BIDX chunk (a selection would lose them)");
        }
    }

    // The jump from the previous block of the fiber to this one is within
    // the chunk's bound (selections rely on it to bound blocks by headers).
    void check_join(std::uint64_t block, const float* p, std::uint32_t n) {
        if (index_ && index_->max_join >= 0 && block_in_fiber_ > 1) {
            const double dx = double(p[0]) - last_[0], dy = double(p[1]) - last_[1], dz = double(p[2]) - last_[2];
            if (std::sqrt(dx * dx + dy * dy + dz * dz) > double(index_->max_join))
                fail("block " + std::to_string(block) +
                     " starts farther from the previous block's end than the BIDX chunk says (a selection would lose it)");
        }
        std::copy(p + 3 * (n - 1), p + 3 * n, last_);
    }

    // Fibers in order: the LUT gives their block counts, the index their
    // point counts (every block but a fiber's last is full) and groups.
    void next_block() {
        if (started_) {
            while (block_in_fiber_ >= file_.block_count(fiber_)) end_fiber(), ++fiber_, block_in_fiber_ = 0, fiber_points_ = 0;
        } else {
            started_ = true;
            while (file_.block_count(fiber_) == 0) check_fiber(), ++fiber_;
        }
        ++block_in_fiber_;
    }
    void end_fiber() {
        check_fiber();
        if (index_) group_base_ += detail::index_groups_of_fiber(file_.block_count(fiber_), index_->group_blocks);
    }
    void check_fiber() const {
        if (!index_) return;
        const std::uint64_t nb = file_.block_count(fiber_), last = index_->last_block_points[fiber_];
        const std::uint64_t said = nb == 0 ? 0 : (nb - 1) * file_.header().points_per_block + last;
        if ((nb == 0) != (last == 0) || said != fiber_points_)
            fail("fiber " + std::to_string(fiber_) + " holds " + std::to_string(fiber_points_) +
                 " points, the BIDX chunk says " + std::to_string(said));
    }

    const FftFile& file_;
    DecodeContext ctx_;
    std::optional<detail::IndexChunk> index_;
    std::optional<detail::IndexBoxDecoder> boxes_;  // versions 1 and 2
    std::vector<Aabb> block_boxes_;                 // version 3
    std::vector<float> xyz_;
    std::uint64_t fiber_ = 0, block_in_fiber_ = 0, fiber_points_ = 0, points_ = 0, group_base_ = 0;
    bool started_ = false;
    float last_[3] = {};  // the previous block's last point
};

}  // namespace

VerifyReport verify_fft_file(const std::string& path, const std::function<void(double)>& progress,
                             const VerifyOptions& options) {
    // Header, LUT and trailer are structurally checked, and their hashes compared, at open.
    const FftFile file(path, {.verify_checksums = true, .ignore_trailer = options.ignore_trailer});
    const FftHeader& h = file.header();
    VerifyReport r;
    r.has_checksum = file.checksums() != nullptr;
    r.blocks = h.blocks;
    r.ignored_trailing_bytes = file.ignored_trailing_bytes();
    BlockCrossCheck cross(file);
    r.index_checked = cross.checks_index();
    // Whole checksum groups at a time, so that no block is read twice.
    const std::uint64_t group = r.has_checksum ? file.checksums()->group_blocks : kDefaultChecksumGroupBlocks;
    const std::uint64_t step = std::max<std::uint64_t>(1, (std::uint64_t{4} << 20) / h.block_bytes() / group) * group;
    std::vector<std::uint8_t> buf;
    for (std::uint64_t b = 0; b < h.blocks; b += step) {
        const std::uint64_t n = std::min<std::uint64_t>(step, h.blocks - b);
        buf.resize(n * h.block_bytes());
        file.read_blocks(b, n, buf.data());  // checks structure, block identities and the groups' hashes
        cross.add(b, n, buf.data());
        r.bytes_read += buf.size();
        if (progress) progress(double(b + n) / double(h.blocks));
    }
    r.points = cross.finish();
    if (r.has_checksum) r.groups = file.checksums()->group_count(h.blocks);
    if (h.packed()) r.bytes_read = h.packed_block_bytes;  // read packed, counted expanded above
    r.bytes_read += h.blocks_offset();
    return r;
}

}  // namespace fiblet
