// IndexBuilder: block boxes quantized as blocks are written, so that the
// index costs no extra pass over the data.
#include <algorithm>
#include <cmath>
#include <limits>

#include "fiblet/block_index.hpp"
#include "fiblet/error.hpp"
#include "select/box_stream.hpp"
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

struct IndexBuilder::Coder {
    explicit Coder(const FftHeader& h) : grid(detail::IndexGrid::for_blocks(h)), stream(grid.min_levels) {}
    // Codes the pending boxes after those coded already.
    void code_pending() {
        for (const Pending& p : pending) stream.add(p.box, p.first_of_fiber);
        pending.clear();
    }
    struct Pending {
        std::optional<detail::GridBox> box;
        bool first_of_fiber;
    };
    detail::IndexGrid grid;
    std::vector<Pending> pending;
    detail::BoxStreamEncoder stream;
    bool coded = false;  // the stream holds boxes
};

IndexBuilder::IndexBuilder() = default;
IndexBuilder::IndexBuilder(const FftHeader& header) : header_(header), coder_(std::make_unique<Coder>(header)) {}
IndexBuilder::IndexBuilder(const IndexBuilder& o)
    : header_(o.header_), coder_(o.coder_ ? std::make_unique<Coder>(*o.coder_) : nullptr), blocks_(o.blocks_),
      last_points_(o.last_points_), open_fiber_blocks_(o.open_fiber_blocks_), layout_ok_(o.layout_ok_),
      unbounded_(o.unbounded_), max_sphere_radius_(o.max_sphere_radius_), max_join_(o.max_join_),
      last_point_(o.last_point_) {}
IndexBuilder& IndexBuilder::operator=(const IndexBuilder& o) {
    if (this != &o) *this = IndexBuilder(o);
    return *this;
}
IndexBuilder::IndexBuilder(IndexBuilder&&) noexcept = default;
IndexBuilder& IndexBuilder::operator=(IndexBuilder&&) noexcept = default;
IndexBuilder::~IndexBuilder() = default;

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
    const auto box = coder_->grid.quantize(bounds_of(xyz, n));
    unbounded_ += !box;
    coder_->pending.push_back({box, open_fiber_blocks_ == 0});
    ++blocks_, ++open_fiber_blocks_;
    if (last_of_fiber) {
        last_points_.push_back(std::uint16_t(n));
        open_fiber_blocks_ = 0;
    } else if (n != header_.points_per_block) {
        layout_ok_ = false;  // only a fiber's last block may be partial
    }
}

void IndexBuilder::append(const IndexBuilder& later) {
    if (later.coder_->coded) throw Error(Errc::invalid_argument, "IndexBuilder::append: the later part has coded boxes");
    layout_ok_ = layout_ok_ && open_fiber_blocks_ == 0;  // blocks of a fiber are added to one builder
    coder_->code_pending();
    coder_->pending = later.coder_->pending;
    coder_->code_pending();
    coder_->coded = coder_->coded || !later.coder_->pending.empty();
    blocks_ += later.blocks_;
    last_points_.insert(last_points_.end(), later.last_points_.begin(), later.last_points_.end());
    layout_ok_ = layout_ok_ && later.layout_ok_ && later.open_fiber_blocks_ == 0;
    unbounded_ += later.unbounded_;
    max_sphere_radius_ = std::max(max_sphere_radius_, later.max_sphere_radius_);
    max_join_ = std::max(max_join_, later.max_join_);
    last_point_ = later.last_point_;
}

void IndexBuilder::clear() {
    coder_ = std::make_unique<Coder>(header_);
    last_points_.clear();
    blocks_ = 0;
    open_fiber_blocks_ = 0;
    layout_ok_ = true;
    unbounded_ = 0;
    max_sphere_radius_ = 0;
    max_join_ = 0;
}

std::optional<TrailerChunk> IndexBuilder::finish() const {
    if (!layout_ok_ || open_fiber_blocks_ != 0) return std::nullopt;
    Coder all = *coder_;
    all.code_pending();
    detail::IndexChunk c;
    c.grid = all.grid;
    c.fibers = last_points_.size();
    c.blocks = blocks_;
    c.max_sphere_radius = max_sphere_radius_;
    // Rounded up, with room for the float rounding of the readers' tests.
    c.max_join = std::nextafter(float(max_join_ * (1 + 1e-6)), std::numeric_limits<float>::infinity());
    c.last_block_points = last_points_;
    return TrailerChunk{kBlockIndexTag, detail::serialize_index_chunk(c, header_, all.stream.finish())};
}

}  // namespace fiblet
