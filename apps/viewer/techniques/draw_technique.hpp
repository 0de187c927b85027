// A drawing style of the viewer (lines, tubes, ...): what turns the blocks
// the shared GPU selection and decode produce into pixels. The Renderer
// owns the per-frame work every style shares (clearing, culling, level of
// detail, batched decoding) and calls one technique per frame; each
// technique is one small module under techniques/ with its shaders beside it.
#pragma once

#include <cstdint>
#include <memory>

#include "fiblet/view.hpp"
#include "gl/gl_objects.hpp"
#include "scene/gpu_scene.hpp"
#include "fiblet_viewer/render_options.hpp"

namespace fiblet::viewer {

struct OcclusionVolume;

// Vertices of the box proxy of the ray-cast styles (shaders/box_proxy.glsl).
inline constexpr unsigned kBoxProxyVertices = 36;

// What a technique draws from in one frame.
struct FrameInputs {
    const GpuScene& scene;
    const Camera& camera;
    const RenderOptions& options;
    bool use_list;  // batches are the fine list's blocks (else blocks first + i)
    const OcclusionVolume* occlusion = nullptr;  // --ao: the chord-based volume (voxel_rt/chord_occlusion.hpp)
};

// A decoded batch: slot i of `points` (and of `tangents`, when the technique
// asked for them) holds block list[first + i] (or first + i) as BlockDecoder
// documents; the fine list stays bound at binding::kFineList.
struct DecodedBatch {
    GLuint points = 0, tangents = 0;
    std::uint32_t first = 0, count = 0;
};

class DrawTechnique {
public:
    virtual ~DrawTechnique() = default;

    // How far (mm) what it draws reaches beyond the fibers' centre lines:
    // culling spheres grow by this much.
    virtual float reach_mm(const GpuScene&, const RenderOptions&) const { return 0; }
    // Whether the decoder must also write each point's unit tangent.
    virtual bool needs_tangents() const { return false; }

    // Called once per frame before the batches (uniforms, per-frame buffers).
    virtual void begin_frame(const FrameInputs&) {}
    // Draws one decoded batch; the next batch reuses the buffers.
    virtual void draw_batch(const FrameInputs&, const DecodedBatch&) = 0;
    // Draws `count` coarse blocks of the coarse list (bound at
    // binding::kCoarseList): blocks the level of detail reduced to one
    // segment each, from their first point to the next block's first point.
    virtual void draw_coarse(const FrameInputs&, std::uint32_t count) = 0;

    // Sorted transparency (transparency/sorted_chunks.hpp): whether the
    // technique draws chunks, and draws them: slot i of the decoded batch
    // holds the block of sorted entry fineList[batch.first + i] (the fine
    // list, bound at binding::kFineList, holds block * chunks_per_block +
    // chunk), and only that chunk's segments, [chunk, chunk + 1) *
    // chunk_segments of the block, are drawn, slot after slot.
    virtual bool draws_chunks() const { return false; }
    virtual void draw_chunks(const FrameInputs&, const DecodedBatch&, std::uint32_t /*chunk_segments*/,
                             std::uint32_t /*chunks_per_block*/) {}
};

}  // namespace fiblet::viewer
