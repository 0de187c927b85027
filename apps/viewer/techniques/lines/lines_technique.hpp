// Illuminated one-pixel (or wider) lines: each decoded segment a GL line,
// each coarse block one segment (techniques/lines/*.glsl).
#pragma once

#include "techniques/draw_technique.hpp"

namespace fiblet::viewer {

class LinesTechnique final : public DrawTechnique {
public:
    LinesTechnique();
    void begin_frame(const FrameInputs& in) override;
    void draw_batch(const FrameInputs& in, const DecodedBatch& batch) override;
    void draw_coarse(const FrameInputs& in, std::uint32_t count) override;

private:
    GlProgram fine_, coarse_;
};

}  // namespace fiblet::viewer
