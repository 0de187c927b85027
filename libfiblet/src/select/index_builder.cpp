// IndexBuilder: block boxes quantized as blocks are written, so that the
// index costs no extra pass over the data.
#include <algorithm>
#include <cmath>
#include <limits>

#include "fiblet/block_index.hpp"
#include "fiblet/error.hpp"
#include "select/index_chunk.hpp"

namespace fiblet {

namespace {

Aabb bounds_of(const float* xyz, std::uint32_t n) {
    Aabb b{{xyz[0], xyz[1], xyz[2]}, {xyz[0], xyz[1], xyz[2]}};
    for (std::uint32_t k = 1; k < n; ++k) {
        const float* p = xyz + 3 * k;
        b.min = {std::min(b.min.x, p[0]), std::min(b.min.y, p[1]), std::min(b.min.z, p[2])};
        b.max = {std::max(b.max.x, p[0]), std::max(b.max.y, p[1]), std::max(b.max.z, p[2])};
    }
    return b;
}

}  // namespace

IndexBuilder::IndexBuilder(const FftHeader& header, unsigned bits_per_box, std::uint32_t group_blocks)
    : header_(header), bits_(bits_per_box), group_blocks_(group_blocks) {
    if (bits_per_box < 8 || bits_per_box > 32) throw Error(Errc::invalid_argument, "index bits per box must be in [8, 32]");
    if (group_blocks == 0) throw Error(Errc::invalid_argument, "index groups must hold at least one block");
    const auto g = detail::IndexGrid::for_header(header, bits_per_box, group_blocks);
    grid_ = {g.origin, g.cell, g.min_levels, g.extent_levels};
}

void IndexBuilder::add_fiber(std::span<const Vec3f> decoded) {
    static_assert(sizeof(Vec3f) == 3 * sizeof(float));
    const std::uint32_t ppb = header_.points_per_block;
    if (decoded.empty()) {
        last_points_.push_back(0);
        return;
    }
    for (std::size_t i = 0; i < decoded.size(); i += ppb) {
        const auto n = std::uint32_t(std::min<std::size_t>(ppb, decoded.size() - i));
        add_block(&decoded[i].x, n, i + n == decoded.size());
    }
}

void IndexBuilder::add_block(const float* xyz, std::uint32_t n, bool last_of_fiber) {
    const Vec3f p0{xyz[0], xyz[1], xyz[2]};
    if (open_fiber_blocks_ > 0) {  // the previous block is of the same fiber
        const double dx = double(p0.x) - last_point_.x, dy = double(p0.y) - last_point_.y,
                     dz = double(p0.z) - last_point_.z;
        max_join_ = std::max(max_join_, std::sqrt(dx * dx + dy * dy + dz * dz));
    }
    last_point_ = {xyz[3 * (n - 1)], xyz[3 * (n - 1) + 1], xyz[3 * (n - 1) + 2]};
    const Vec3f p1 = n >= 2 ? Vec3f{xyz[3], xyz[4], xyz[5]} : p0;
    add_box(bounds_of(xyz, n), n, last_of_fiber, block_bounding_sphere(header_, p0, p1, n).radius);
}

void IndexBuilder::add_box(const Aabb& box, std::uint32_t n, bool last_of_fiber, float sphere_radius) {
    if (group_fill_ == 0) {
        group_box_ = box;
    } else {
        const Aabb& b = box;
        Aabb& g = group_box_;
        g.min = {std::min(g.min.x, b.min.x), std::min(g.min.y, b.min.y), std::min(g.min.z, b.min.z)};
        g.max = {std::max(g.max.x, b.max.x), std::max(g.max.y, b.max.y), std::max(g.max.z, b.max.z)};
    }
    ++group_fill_, ++blocks_;
    max_sphere_radius_ = std::max(max_sphere_radius_, sphere_radius);
    ++open_fiber_blocks_;
    if (last_of_fiber) {
        last_points_.push_back(std::uint16_t(n));
        open_fiber_blocks_ = 0;
    } else if (n != header_.points_per_block) {
        layout_ok_ = false;  // only a fiber's last block may be partial
    }
    if (last_of_fiber || group_fill_ == group_blocks_) close_group();
}

void IndexBuilder::close_group() {
    const detail::IndexGrid g{grid_.origin, grid_.cell, grid_.min_levels, grid_.extent_levels, bits_};
    const std::uint32_t code = g.encode(group_box_);
    unbounded_ += code == g.unbounded_code();
    codes_.push_back(code);
    group_fill_ = 0;
}

void IndexBuilder::append(const IndexBuilder& later) {
    layout_ok_ = layout_ok_ && open_fiber_blocks_ == 0;  // groups never span two fibers
    codes_.insert(codes_.end(), later.codes_.begin(), later.codes_.end());
    blocks_ += later.blocks_;
    last_points_.insert(last_points_.end(), later.last_points_.begin(), later.last_points_.end());
    layout_ok_ = layout_ok_ && later.layout_ok_ && later.open_fiber_blocks_ == 0;
    unbounded_ += later.unbounded_;
    max_sphere_radius_ = std::max(max_sphere_radius_, later.max_sphere_radius_);
    max_join_ = std::max(max_join_, later.max_join_);
    last_point_ = later.last_point_;
}

void IndexBuilder::clear() {
    codes_.clear();
    last_points_.clear();
    group_fill_ = 0, blocks_ = 0;
    open_fiber_blocks_ = 0;
    layout_ok_ = true;
    unbounded_ = 0;
    max_sphere_radius_ = 0;
    max_join_ = 0;
}

std::optional<TrailerChunk> IndexBuilder::finish() const {
    if (!layout_ok_ || open_fiber_blocks_ != 0) return std::nullopt;
    detail::IndexChunk c;
    c.grid = {grid_.origin, grid_.cell, grid_.min_levels, grid_.extent_levels, bits_};
    c.group_blocks = group_blocks_;
    c.fibers = last_points_.size();
    c.blocks = blocks_;
    c.groups = codes_.size();
    c.max_sphere_radius = max_sphere_radius_;
    // Rounded up, with room for the float rounding of the readers' tests.
    c.max_join = std::nextafter(float(max_join_ * (1 + 1e-6)), std::numeric_limits<float>::infinity());
    c.last_block_points = last_points_;
    c.codes = codes_;
    return TrailerChunk{kBlockIndexTag, detail::serialize_index_chunk(c, header_)};
}

}  // namespace fiblet
