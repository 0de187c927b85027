#include "scene/fiber_streaming.hpp"

#include <epoxy/gl.h>
#include <fmt/core.h>

#include <algorithm>
#include <array>

#include "fiblet/decode.hpp"
#include "fiblet/direction_code.hpp"
#include "fiblet/error.hpp"
#include "fiblet/select.hpp"

namespace fiblet::viewer {

namespace {

// Per block: the block, its fiber index, the renderer's fine, coarse and
// decision lists; per fiber: points, end point (vec4), end fraction,
// colour (vec4), radius.
constexpr std::uint64_t kListBytesPerBlock = 4 + 3 * 4;
constexpr std::uint64_t kBytesPerFiber = 4 + 16 + 4 + 16 + 4;

// Fibers' ranks: the level of detail keeps the lowest (fiber_streaming.hpp).
std::uint64_t rank_of(std::uint64_t fiber) { return splitmix64(fiber); }
constexpr int kRankBucketBits = 16;  // the threshold's resolution: 1/65536 of the candidates

}  // namespace

std::uint64_t scene_gpu_bytes(const FftHeader& h, std::uint64_t fibers, std::uint64_t blocks, bool point_values) {
    const std::uint64_t per_block = h.block_bytes() + kListBytesPerBlock + (point_values ? 4ull * h.points_per_block : 0);
    return blocks * per_block + fibers * kBytesPerFiber;
}

std::uint64_t scene_constant_bytes(const FftHeader& h) {
    const DecodeContext ctx(h);
    const std::uint64_t codes = ctx.table16 ? ctx.table16->code_count() : 256;
    return codes * 48 + 3 * 16;  // a mat3 of vec4 columns a code
}

std::uint64_t default_gpu_budget() {
    // Both extensions report KiB.
    if (epoxy_has_gl_extension("GL_NVX_gpu_memory_info")) {
        GLint kib = 0;
        glGetIntegerv(GL_GPU_MEMORY_INFO_CURRENT_AVAILABLE_VIDMEM_NVX, &kib);
        if (kib > 0) return std::uint64_t(kib) * 1024 / 2;
    }
    if (epoxy_has_gl_extension("GL_ATI_meminfo")) {
        std::array<GLint, 4> kib{};
        glGetIntegerv(GL_VBO_FREE_MEMORY_ATI, kib.data());
        if (kib[0] > 0) return std::uint64_t(kib[0]) * 1024 / 2;
    }
    return 1ull << 30;
}

FiberStreaming::FiberStreaming(const FftFile& file, std::uint64_t budget_bytes, bool point_values)
    : file_(&file),
      budget_(budget_bytes ? budget_bytes : default_gpu_budget()),
      constant_bytes_(scene_constant_bytes(file.header())),
      point_values_(point_values) {
    const FftHeader& h = file.header();
    const std::uint64_t per_slot = point_values ? std::max<std::uint64_t>(h.block_bytes(), 4ull * h.points_per_block)
                                                : h.block_bytes();
    block_limit_ = max_storage_buffer_bytes() / per_slot;
    if (fits(h.fibers, h.blocks, budget_)) return;
    index_ = std::make_shared<const BlockIndex>(BlockIndex::load(file));
    std::vector<std::uint64_t> all(std::size_t(h.fibers));
    for (std::size_t f = 0; f < all.size(); ++f) all[f] = f;
    overview_ = densest_within(all, kOverviewBlocks, budget_ / 4);
    std::uint64_t blocks = 0;
    for (const std::uint64_t f : overview_.fibers) blocks += file.block_count(f);
    overview_bytes_ = scene_gpu_bytes(h, overview_.fibers.size(), blocks, point_values_) + constant_bytes_;
}

bool FiberStreaming::fits(std::uint64_t fibers, std::uint64_t blocks, std::uint64_t max_bytes) const {
    return blocks <= block_limit_ &&
           scene_gpu_bytes(file_->header(), fibers, blocks, point_values_) + constant_bytes_ <= max_bytes;
}

// The candidates of rank below the highest threshold (a multiple of
// 2^(64 - kRankBucketBits)) whose fibers fit: blocks summed per rank bucket,
// then the buckets taken in order while they fit.
FiberSubset FiberStreaming::densest_within(const std::vector<std::uint64_t>& candidates, std::uint64_t max_blocks,
                                           std::uint64_t max_bytes) const {
    std::vector<std::uint64_t> blocks(std::size_t(1) << kRankBucketBits), fibers(blocks.size());
    for (const std::uint64_t f : candidates) {
        const std::size_t bucket = std::size_t(rank_of(f) >> (64 - kRankBucketBits));
        blocks[bucket] += file_->block_count(f), ++fibers[bucket];
    }
    std::uint64_t total_blocks = 0, total_fibers = 0;
    std::size_t buckets = 0;
    for (; buckets < blocks.size(); ++buckets) {
        const std::uint64_t b = total_blocks + blocks[buckets], n = total_fibers + fibers[buckets];
        if (b > max_blocks || !fits(n, b, max_bytes)) break;
        total_blocks = b, total_fibers = n;
    }
    FiberSubset out{{}, index_};
    out.fibers.reserve(std::size_t(total_fibers));
    for (const std::uint64_t f : candidates)
        if ((rank_of(f) >> (64 - kRankBucketBits)) < buckets) out.fibers.push_back(f);
    return out;
}

FiberSubset FiberStreaming::visible(const Camera& camera, float margin_mm) const {
    std::vector<std::uint64_t> bits;
    index_->blocks_near_frustum(frustum_from_camera(camera), margin_mm, bits);
    auto seen = [&](std::uint64_t b) { return b / 64 < bits.size() && (bits[b / 64] >> (b % 64) & 1); };
    std::vector<std::uint64_t> candidates;
    for (std::uint64_t f = 0; f < file_->header().fibers; ++f) {
        const std::uint64_t first = file_->first_block(f), end = first + file_->block_count(f);
        for (std::uint64_t b = first; b < end; ++b)
            if (seen(b)) {
                candidates.push_back(f);
                break;
            }
    }
    return densest_within(candidates, ~0ull, budget_ > overview_bytes_ ? budget_ - overview_bytes_ : 0);
}

const GpuScene& hold_view(std::optional<GpuScene>& part, const GpuScene& overview, const FftFile& file,
                          const GpuPrograms& programs, const FiberStreaming& streaming, const Camera& camera,
                          float margin_mm) {
    FiberSubset seen = streaming.visible(camera, margin_mm);
    if (part)
        part->reside(file, programs, std::move(seen));
    else
        part.emplace(overview, file, programs, std::move(seen));
    return *part;
}

}  // namespace fiblet::viewer
