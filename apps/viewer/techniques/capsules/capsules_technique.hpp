// Capsules: each decoded segment swept by a sphere of the option's radius,
// ray cast exactly inside its oriented box (capsule_boxes.vert.glsl,
// capsules.frag.glsl). The tube of the polyline itself, with no spline; the
// primitive of voxel ray tracing. One box per 0.1 mm step overlaps its
// neighbours several times at usual radii. Coarse blocks stay lines.
#pragma once

#include "techniques/draw_technique.hpp"
#include "techniques/lines/lines_technique.hpp"
#include "techniques/tubes/tube_spline.hpp"

namespace fiblet::viewer {

class CapsulesTechnique final : public DrawTechnique {
public:
    CapsulesTechnique();

    float reach_mm(const GpuScene& scene, const RenderOptions& o) const override { return tube_radius_reach(scene, o); }
    void begin_frame(const FrameInputs& in) override;
    void draw_batch(const FrameInputs& in, const DecodedBatch& batch) override;
    void draw_coarse(const FrameInputs& in, std::uint32_t count) override;
    bool draws_chunks() const override { return true; }
    void draw_chunks(const FrameInputs& in, const DecodedBatch& batch, std::uint32_t chunk_segments,
                     std::uint32_t chunks_per_block) override;

private:
    void draw_slots(const FrameInputs& in, const DecodedBatch& batch, bool use_list, std::uint32_t slot_segments,
                    std::uint32_t chunks_per_block);
    GlProgram draw_;
    LinesTechnique coarse_lines_;
};

}  // namespace fiblet::viewer
