// The order in which a frame's fine blocks reach its technique: in the fine
// list's order a decoded batch at a time (ListOrder: opaque frames and
// unsorted blending), or an order of transparency/ (sorted chunks,
// voxlines). The technique registry picks the order with the technique;
// the Renderer draws whatever pair it is given.
#pragma once

#include <cstdint>

#include "gl/gpu_timer.hpp"
#include "scene/block_decoder.hpp"
#include "techniques/draw_technique.hpp"

namespace fiblet::viewer {

// The frame's fine blocks as the Renderer's selection left them.
struct FrameBlocks {
    const BlockDecoder& decoder;
    GpuDecoder kind;
    GLuint fine_list;     // bound at binding::kFineList while in.use_list
    std::uint32_t count;  // the fine list's first `count` blocks (else blocks 0..count-1)
    GpuTimer& timer;      // each order times its decode and draw stages
};

class FrameOrder {
public:
    virtual ~FrameOrder() = default;
    virtual void draw(const FrameInputs& in, const FrameBlocks& blocks, DrawTechnique& technique) = 0;
    // GPU memory the order keeps between frames.
    virtual std::uint64_t gpu_bytes() const { return 0; }
};

// Decoded a batch at a time and drawn in list order.
class ListOrder final : public FrameOrder {
public:
    void draw(const FrameInputs& in, const FrameBlocks& blocks, DrawTechnique& technique) override;
};

}  // namespace fiblet::viewer
