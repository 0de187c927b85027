// Whole-brain files on a GPU memory budget. A file whose scene would take
// more GPU memory than the budget is held a part at a time: whole fibers,
// chosen by visibility (a box of the block index meets the view, so no block
// is read to decide) and by a level of detail in fiber density. Every fiber
// has a fixed rank (splitmix64 of its index); a level keeps the fibers of
// lowest rank that fit, so a denser level holds every fiber of a sparser one
// and the picture only fills in as it refines.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include "fiblet/block_index.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/view.hpp"
#include "scene/gpu_scene.hpp"

namespace fiblet::viewer {

// GPU bytes a scene of `fibers` fibers and `blocks` blocks takes beyond
// scene_constant_bytes: its buffers (gpu_scene.hpp: blocks, per-block fiber,
// per-fiber tables, colours, radii, point values when asked) and the
// renderer's per-block lists.
std::uint64_t scene_gpu_bytes(const FftHeader& header, std::uint64_t fibers, std::uint64_t blocks, bool point_values);
// What every scene of a file takes: its direction code's frames and the
// one-element buffers of absent attributes.
std::uint64_t scene_constant_bytes(const FftHeader& header);

// The default budget: half the GPU memory the driver says is free
// (GL_NVX_gpu_memory_info, GL_ATI_meminfo), else 1 GiB. Needs a current context.
std::uint64_t default_gpu_budget();
// Blocks of the first level shown: a first frame within ~2 s on a software
// rasterizer (llvmpipe draws ~3 M segments a second at 1080p).
inline constexpr std::uint64_t kOverviewBlocks = 32768;

class FiberStreaming {
public:
    // Loads the file's block index only when the whole file exceeds the
    // budget (0: default_gpu_budget()). Throws Error{fft_format} for a
    // malformed index.
    FiberStreaming(const FftFile& file, std::uint64_t budget_bytes, bool point_values);

    bool streams() const { return index_ != nullptr; }  // the whole file exceeds the budget
    std::uint64_t budget_bytes() const { return budget_; }
    const BlockIndex& index() const { return *index_; }

    // The fibers of the first frame, and of frames drawn while the view
    // moves: the lowest ranks within kOverviewBlocks blocks (and a quarter
    // of the budget). Only when streams().
    const FiberSubset& overview() const { return overview_; }
    // The fibers `camera` may see (a block's box meets its frustum grown by
    // `margin_mm`, what a style draws beyond the centre line), the lowest
    // ranks first, within the budget less the overview's share. Only when
    // streams().
    FiberSubset visible(const Camera& camera, float margin_mm) const;

private:
    FiberSubset densest_within(const std::vector<std::uint64_t>& candidates, std::uint64_t max_blocks,
                               std::uint64_t max_bytes) const;
    bool fits(std::uint64_t fibers, std::uint64_t blocks, std::uint64_t max_bytes) const;

    const FftFile* file_;
    std::uint64_t budget_;
    std::uint64_t constant_bytes_;      // scene_constant_bytes
    std::uint64_t overview_bytes_ = 0;  // of the budget, kept for the overview
    FiberSubset overview_;
    bool point_values_;
    std::uint64_t block_limit_;  // what one storage buffer holds
    std::shared_ptr<const BlockIndex> index_;
};

// `part` made to hold the fibers `camera` sees (FiberStreaming::visible):
// held again, or made the first time with `overview`'s colours, radii and
// point values. Only when `streaming` streams.
const GpuScene& hold_view(std::optional<GpuScene>& part, const GpuScene& overview, const FftFile& file,
                          const GpuPrograms& programs, const FiberStreaming& streaming, const Camera& camera,
                          float margin_mm);

}  // namespace fiblet::viewer
