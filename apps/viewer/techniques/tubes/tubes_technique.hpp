// Tubes: each fiber a sphere of the option's radius swept along a C¹
// spline through every s-th decoded point (tube_spline.hpp), ray cast per
// quadratic piece inside its oriented box (tube_pieces.comp.glsl,
// tube_boxes.vert.glsl, tubes.frag.glsl). Coarse blocks (level of detail,
// a few pixels on screen) stay lines.
#pragma once

#include <memory>

#include "techniques/draw_technique.hpp"
#include "techniques/lines/lines_technique.hpp"
#include "techniques/tubes/tube_spline.hpp"

namespace fiblet::viewer {

class TubesTechnique final : public DrawTechnique {
public:
    // `tangent_scale`: c of tube_spline.hpp; other values only to show in
    // tests that the renderer's agreement depends on it.
    explicit TubesTechnique(float tangent_scale = kBezierTangentScale);

    float reach_mm(const GpuScene& scene, const RenderOptions& o) const override { return tube_radius_reach(scene, o); }
    bool needs_tangents() const override { return true; }
    void begin_frame(const FrameInputs& in) override;
    void draw_batch(const FrameInputs& in, const DecodedBatch& batch) override;
    void draw_coarse(const FrameInputs& in, std::uint32_t count) override;
    bool draws_chunks() const override { return true; }
    void draw_chunks(const FrameInputs& in, const DecodedBatch& batch, std::uint32_t chunk_segments,
                     std::uint32_t chunks_per_block) override;

    // The pieces of a batch (first step of draw_batch), left in
    // pieces_buffer() and bound at binding::kTubePieces; returns how many
    // pieces the buffer holds (empty ones included).
    std::uint32_t build_pieces(const FrameInputs& in, const DecodedBatch& batch);
    GLuint pieces_buffer() const { return pieces_.get(); }
    // Largest pieces buffer (default: the driver's largest storage buffer);
    // a batch whose pieces take more is built and drawn in runs of slots.
    // Tests lower it to check that runs draw the same image.
    void set_piece_buffer_limit(std::uint64_t bytes) { piece_buffer_limit_ = bytes; }

private:
    std::uint32_t segments_per_slot(const FrameInputs& in, std::uint32_t chunk_segments,
                                    std::uint32_t chunks_per_block) const;
    // The pieces of slots [first_slot, first_slot + slots) of the batch.
    std::uint32_t build_pieces(const FrameInputs& in, const DecodedBatch& batch, bool use_list,
                               std::uint32_t chunk_segments, std::uint32_t chunks_per_block, std::uint32_t first_slot,
                               std::uint32_t slots);
    void draw_slots(const FrameInputs& in, const DecodedBatch& batch, bool use_list, std::uint32_t chunk_segments,
                    std::uint32_t chunks_per_block);
    void draw_pieces(std::uint32_t pieces);
    float tangent_scale_;
    GlProgram build_, draw_;
    GlBuffer pieces_;
    std::uint64_t pieces_capacity_ = 0;
    std::uint64_t piece_buffer_limit_;
    LinesTechnique coarse_lines_;
};

}  // namespace fiblet::viewer
