// Voxlines (Osman, Pereira, van de Wetering, Chamberland): the segments
// binned into voxels of 10 mm by their first point (a streamline's run of
// points in a voxel, plus the step into the next one: a voxline), and inside
// every voxel three precomputed orders, by (p0 + p1) . axis for x, y and z.
// A frame draws the voxels back to front, each in the order (forwards or
// backwards) of the axis closest to the direction from the voxel to the eye.
// Built once per scene from the GPU decoder's points (it keeps every segment:
// 44 bytes each on the GPU), drawn as TransparentLines are.
#pragma once

#include <cstdint>
#include <vector>

#include <memory>

#include "scene/gpu_programs.hpp"
#include "techniques/frame_order.hpp"

namespace fiblet::viewer {

class Voxlines {
public:
    static constexpr float kVoxelMm = 10;  // the paper's voxel size

    Voxlines(const GpuScene& scene, const GpuPrograms& programs, GpuDecoder kind);

    std::uint64_t scene_generation() const { return scene_generation_; }  // built from
    std::uint64_t gpu_bytes() const { return gpu_bytes_; }
    void draw(const FrameInputs& in);

private:
    struct Voxel {
        std::uint32_t index;         // x + nx (y + ny z)
        std::uint32_t first, count;  // its range in each axis order
    };
    std::vector<std::uint32_t> back_to_front(const Camera& camera) const;  // indices into voxels_
    Vec3f voxel_center(std::uint32_t index) const;

    std::uint64_t scene_generation_;
    Vec3f origin_;
    std::uint32_t nx_ = 1, ny_ = 1, nz_ = 1;
    std::uint32_t segments_ = 0;
    std::vector<Voxel> voxels_;  // the non-empty ones
    GlBuffer segment_ends_, orders_;
    std::uint64_t gpu_bytes_ = 0;
    GlProgram program_;
};

// Voxlines as a frame's order (lines only): built on a scene's first frame,
// drawn instead of the decoded blocks, with the transparent lines' shading.
class VoxlineOrder final : public FrameOrder {
public:
    explicit VoxlineOrder(const GpuPrograms& programs) : programs_(programs) {}
    void draw(const FrameInputs& in, const FrameBlocks& blocks, DrawTechnique& technique) override;
    std::uint64_t gpu_bytes() const override { return voxlines_ ? voxlines_->gpu_bytes() : 0; }

private:
    const GpuPrograms& programs_;
    std::unique_ptr<Voxlines> voxlines_;
};

}  // namespace fiblet::viewer
