// Lines drawn for blending (transparency/): every segment a box whose
// fragment shader keeps the pixels of the diamond-exit rule
// (diamond_exit.glsl), so that a fiber blends once per pixel it crosses, the
// same on every driver. As a technique it draws whole decoded blocks in the
// renderer's order (unsorted blending), or sorted chunks (draw_chunks).
#pragma once

#include "techniques/draw_technique.hpp"

namespace fiblet::viewer {

class TransparentLines final : public DrawTechnique {
public:
    TransparentLines();
    void begin_frame(const FrameInputs& in) override;
    void draw_batch(const FrameInputs& in, const DecodedBatch& batch) override;
    // Transparent frames have no level of detail: nothing is coarse.
    void draw_coarse(const FrameInputs&, std::uint32_t) override {}

    bool draws_chunks() const override { return true; }
    void draw_chunks(const FrameInputs& in, const DecodedBatch& batch, std::uint32_t chunk_segments,
                     std::uint32_t chunks_per_block) override;

    // The program (voxlines.hpp draws with the same uniforms and fragment shader).
    static void set_uniforms(const GlProgram& program, const FrameInputs& in);

private:
    GlProgram program_;
};

}  // namespace fiblet::viewer
