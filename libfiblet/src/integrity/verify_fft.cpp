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

namespace fiblet {

namespace {

// Walks the blocks in file order, a fiber at a time, checking what no
// checksum can (a file may have none, or a writer may have been wrong): the
// header's point count, the index's per-fiber counts and boxes, and that
// every decoded point is finite.
class BlockCrossCheck {
public:
    // Decoded as every reader decodes them: with the file's kept fiber ends.
    BlockCrossCheck(const FftFile& file, const BlockIndex* index) : file_(file), index_(index), ctx_(file) {}

    void add(std::uint64_t first, std::uint64_t count, const std::uint8_t* blocks) {
        const FftHeader& h = file_.header();
        xyz_.resize(3 * count_block_points(ctx_, blocks, count));
        decode_blocks(ctx_, blocks, count, xyz_.data());
        const float* p = xyz_.data();
        for (std::uint64_t b = 0; b < count; ++b) {
            const std::uint32_t n = block_flags(h, blocks + b * h.block_bytes()).point_count;
            check_points(first + b, p, n);
            count_points(n);
            p += 3 * n;
        }
    }

    std::uint64_t finish() const {
        const FftHeader& h = file_.header();
        if (points_ != h.points)
            fail("the blocks hold " + std::to_string(points_) + " points, the header says " + std::to_string(h.points));
        return points_;
    }

private:
    [[noreturn]] void fail(const std::string& what) const {
        throw Error(Errc::fft_format, file_.path() + ": not a valid .fft file: " + what);
    }

    void check_points(std::uint64_t block, const float* p, std::uint32_t n) const {
        const Aabb box = index_ ? index_->block_box(block) : Aabb{};
        for (std::uint32_t i = 0; i < n; ++i, p += 3) {
            if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])))
                fail("block " + std::to_string(block) + " decodes to a non-finite point");
            if (index_ && !(p[0] >= box.min.x && p[0] <= box.max.x && p[1] >= box.min.y && p[1] <= box.max.y &&
                            p[2] >= box.min.z && p[2] <= box.max.z))
                fail("block " + std::to_string(block) +
                     " decodes to points outside its box in the BIDX chunk (a selection would lose them)");
        }
    }

    // Fibers in order: the LUT gives their block counts, the index (when
    // present) their point counts.
    void count_points(std::uint32_t n) {
        while (block_in_fiber_ >= file_.block_count(fiber_)) ++fiber_, block_in_fiber_ = 0, fiber_points_ = 0;
        fiber_points_ += n, points_ += n;
        if (++block_in_fiber_ == file_.block_count(fiber_) && index_ && index_->fiber_points(fiber_) != fiber_points_)
            fail("fiber " + std::to_string(fiber_) + " holds " + std::to_string(fiber_points_) +
                 " points, the BIDX chunk says " + std::to_string(index_->fiber_points(fiber_)));
    }

    const FftFile& file_;
    const BlockIndex* index_;
    DecodeContext ctx_;
    std::vector<float> xyz_;
    std::uint64_t fiber_ = 0, block_in_fiber_ = 0, fiber_points_ = 0, points_ = 0;
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
    std::optional<BlockIndex> index;
    if (file.find_chunk(kBlockIndexTag)) index.emplace(BlockIndex::load(file));
    r.index_checked = index.has_value();
    BlockCrossCheck cross(file, index ? &*index : nullptr);
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
    r.bytes_read += h.blocks_offset();
    return r;
}

}  // namespace fiblet
