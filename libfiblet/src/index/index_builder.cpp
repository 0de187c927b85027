// IndexBuilder: block boxes quantized as blocks are written, so that the
// index costs no extra pass over the data.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "fiblet/block_index.hpp"
#include "fiblet/error.hpp"
#include "core/points_avx2.hpp"
#include "index/box_rans.hpp"
#include "index/index_chunk.hpp"

namespace fiblet {

namespace {

// A block's decoded points (finite), eight at a time where the CPU has AVX2
// (the scan's loop; the index stage of compress -e 0 on the medium
// tractogram 0.0755 -> 0.069 s against the scalar loop's chains of minima).
Aabb bounds_of(const float* xyz, std::uint32_t n) {
    constexpr float inf = std::numeric_limits<float>::infinity();
    float lo[3] = {inf, inf, inf}, hi[3] = {-inf, -inf, -inf};
    std::size_t k = 0;
#ifdef FIBLET_POINTS_AVX2
    if (detail::use_avx2_loops()) k = detail::bounds_avx2(reinterpret_cast<const Vec3f*>(xyz), n, lo, hi);
#endif
    for (; k < n; ++k)
        for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], xyz[3 * k + c]), hi[c] = std::max(hi[c], xyz[3 * k + c]);
    return {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}};
}

}  // namespace

// The boxes as one BIDX version stores them: the only part of the builder
// that differs between the formats.
struct IndexBuilder::Coder {
    virtual ~Coder() = default;
    virtual std::unique_ptr<Coder> clone() const = 0;
    virtual std::unique_ptr<Coder> fresh() const = 0;  // same format and grid, no boxes
    virtual BlockIndexFormat format() const = 0;
    // One block's bounds, in file order.
    virtual void add(const Aabb& box, bool first_of_fiber, bool last_of_fiber) = 0;
    // The boxes of a builder of the same format on the next fibers.
    virtual void append(const Coder& later) = 0;
    // The payload of a chunk with c's common fields filled in.
    virtual std::vector<std::uint8_t> finish(detail::IndexChunk& c, const FftHeader& h) const = 0;
    std::uint64_t unbounded = 0;
};

// Version 2: a fixed-width box code per group of up to 8 blocks of a fiber.
struct IndexBuilder::GroupCoder final : Coder {
    explicit GroupCoder(const FftHeader& h)
        : grid(detail::IndexGrid::for_groups(h, detail::kIndexV2BitsPerBox, detail::kIndexV2GroupBlocks)) {}
    std::unique_ptr<Coder> clone() const override { return std::make_unique<GroupCoder>(*this); }
    std::unique_ptr<Coder> fresh() const override {
        auto c = std::make_unique<GroupCoder>(*this);
        c->codes.clear(), c->fill = 0, c->unbounded = 0;
        return c;
    }
    BlockIndexFormat format() const override { return BlockIndexFormat::group_boxes; }
    void add(const Aabb& b, bool, bool last_of_fiber) override {
        if (fill == 0) {
            group = b;
        } else {
            group.min = {std::min(group.min.x, b.min.x), std::min(group.min.y, b.min.y), std::min(group.min.z, b.min.z)};
            group.max = {std::max(group.max.x, b.max.x), std::max(group.max.y, b.max.y), std::max(group.max.z, b.max.z)};
        }
        if (++fill == detail::kIndexV2GroupBlocks || last_of_fiber) {
            const std::uint32_t code = grid.encode(group);
            unbounded += code == grid.unbounded_code();
            codes.push_back(code);
            fill = 0;
        }
    }
    void append(const Coder& later) override {
        const auto& o = static_cast<const GroupCoder&>(later);
        codes.insert(codes.end(), o.codes.begin(), o.codes.end());
        unbounded += o.unbounded;
    }
    std::vector<std::uint8_t> finish(detail::IndexChunk& c, const FftHeader& h) const override {
        c.version = detail::kIndexChunkV2Version;
        c.grid = grid;
        c.group_blocks = detail::kIndexV2GroupBlocks;
        c.groups = codes.size();
        c.codes = codes;
        return detail::serialize_index_chunk_v2(c, h);
    }
    detail::IndexGrid grid;
    std::vector<std::uint32_t> codes;  // per closed group
    Aabb group{};                      // the open group's bounds
    std::uint32_t fill = 0;            // blocks in the open group
};

// Version 4: a box per block, coded against the previous one once all are
// known (the code's frequencies are the boxes' own).
struct IndexBuilder::BlockCoder final : Coder {
    explicit BlockCoder(const FftHeader& h) : grid(detail::IndexGrid::for_blocks(h)) {}
    explicit BlockCoder(const detail::IndexGrid& g) : grid(g) {}
    std::unique_ptr<Coder> clone() const override { return std::make_unique<BlockCoder>(*this); }
    std::unique_ptr<Coder> fresh() const override { return std::make_unique<BlockCoder>(grid); }
    BlockIndexFormat format() const override { return BlockIndexFormat::block_boxes; }
    void add(const Aabb& b, bool first_of_fiber, bool) override {
        const std::optional<detail::GridBox> box = grid.quantize(b);
        boxes.push_back(box ? detail::pack_cells(*box) : detail::kUnboundedCells);
        unbounded += !box;
        first.push_back(first_of_fiber);
    }
    void append(const Coder& later) override {
        const auto& o = static_cast<const BlockCoder&>(later);
        boxes.insert(boxes.end(), o.boxes.begin(), o.boxes.end());
        first.insert(first.end(), o.first.begin(), o.first.end());
        unbounded += o.unbounded;
    }
    std::vector<std::uint8_t> finish(detail::IndexChunk& c, const FftHeader& h) const override {
        c.version = detail::kIndexChunkVersion;
        c.grid = grid;
        return detail::serialize_index_chunk(c, h, detail::encode_box_rans(boxes, first, grid.min_levels));
    }
    detail::IndexGrid grid;
    std::vector<std::uint64_t> boxes;  // packed (8 bytes a block until finished)
    std::vector<bool> first;  // first block of its fiber
};

IndexBuilder::IndexBuilder() = default;
IndexBuilder::IndexBuilder(const FftHeader& header, BlockIndexFormat format) : header_(header) {
    switch (format) {
    case BlockIndexFormat::group_boxes: coder_ = std::make_unique<GroupCoder>(header); return;
    case BlockIndexFormat::block_boxes: coder_ = std::make_unique<BlockCoder>(header); return;
    }
    throw Error(Errc::invalid_argument, "unknown block index format");
}
IndexBuilder::IndexBuilder(const IndexBuilder& o)
    : header_(o.header_), coder_(o.coder_ ? o.coder_->clone() : nullptr), blocks_(o.blocks_),
      last_points_(o.last_points_), open_fiber_blocks_(o.open_fiber_blocks_), layout_ok_(o.layout_ok_),
      max_sphere_radius_(o.max_sphere_radius_), max_join_(o.max_join_), last_point_(o.last_point_) {}
IndexBuilder& IndexBuilder::operator=(const IndexBuilder& o) {
    if (this != &o) *this = IndexBuilder(o);
    return *this;
}
IndexBuilder::IndexBuilder(IndexBuilder&&) noexcept = default;
IndexBuilder& IndexBuilder::operator=(IndexBuilder&&) noexcept = default;
IndexBuilder::~IndexBuilder() = default;

BlockIndexFormat IndexBuilder::format() const { return coder_->format(); }
std::uint64_t IndexBuilder::unbounded_blocks() const { return coder_->unbounded; }

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
    max_sphere_radius_ = std::max(max_sphere_radius_, block_bounding_sphere(header_, p0, p1, n).radius);
    coder_->add(bounds_of(xyz, n), open_fiber_blocks_ == 0, last_of_fiber);
    ++blocks_, ++open_fiber_blocks_;
    if (last_of_fiber) {
        last_points_.push_back(std::uint16_t(n));
        open_fiber_blocks_ = 0;
    } else if (n != header_.points_per_block) {
        layout_ok_ = false;  // only a fiber's last block may be partial
    }
}

void IndexBuilder::append(const IndexBuilder& later) {
    if (later.coder_->format() != coder_->format())
        throw Error(Errc::invalid_argument, "IndexBuilder::append: the parts are of different index formats");
    layout_ok_ = layout_ok_ && open_fiber_blocks_ == 0;  // blocks of a fiber are added to one builder
    coder_->append(*later.coder_);
    blocks_ += later.blocks_;
    last_points_.insert(last_points_.end(), later.last_points_.begin(), later.last_points_.end());
    layout_ok_ = layout_ok_ && later.layout_ok_ && later.open_fiber_blocks_ == 0;
    max_sphere_radius_ = std::max(max_sphere_radius_, later.max_sphere_radius_);
    max_join_ = std::max(max_join_, later.max_join_);
    last_point_ = later.last_point_;
}

void IndexBuilder::clear() {
    coder_ = coder_->fresh();
    last_points_.clear();
    blocks_ = 0;
    open_fiber_blocks_ = 0;
    layout_ok_ = true;
    max_sphere_radius_ = 0;
    max_join_ = 0;
}

std::optional<TrailerChunk> IndexBuilder::finish() const {
    if (!layout_ok_ || open_fiber_blocks_ != 0) return std::nullopt;
    detail::IndexChunk c;
    c.fibers = last_points_.size();
    c.blocks = blocks_;
    c.max_sphere_radius = max_sphere_radius_;
    // Rounded up, with room for the float rounding of the readers' tests.
    c.max_join = std::nextafter(float(max_join_ * (1 + 1e-6)), std::numeric_limits<float>::infinity());
    c.last_block_points = last_points_;
    return TrailerChunk{kBlockIndexTag, coder_->finish(c, header_)};
}

}  // namespace fiblet
