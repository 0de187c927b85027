// Sorted transparency, fiblet's own: the frame's decoded blocks cut into
// chunks of ~1 mm (10 segments), sorted back to front on the GPU and drawn
// in that order. Nothing per segment is kept between frames: a first pass
// decodes the blocks a batch at a time and keys every chunk by its depth
// bucket (chunk_keys.comp.glsl); a stable counting sort (chunk_count,
// chunk_scan, chunk_scatter) orders the chunks, by block index within a
// bucket (not by the fine list's order, which the culling's atomics vary); a second pass decodes the
// sorted chunks' blocks a batch at a time and draws each chunk through the
// frame's technique (DrawTechnique::draw_chunks: transparent lines, tubes,
// capsules). GL blends in the order the primitives are drawn, and the sort
// has no atomics, so a frame is deterministic.
#pragma once

#include <cstdint>

#include "techniques/frame_order.hpp"

namespace fiblet::viewer {

class SortedChunks final : public FrameOrder {
public:
    static constexpr std::uint32_t kChunkSegments = 10;  // ~1 mm at 0.1 mm steps
    static constexpr std::uint32_t kBuckets = 1024;      // depth buckets across the scene's box
    static constexpr std::uint32_t kLanes = 1024;        // counting sort lanes (chunk_count.comp.glsl)

    SortedChunks();

    // The technique must draw chunks (DrawTechnique::draws_chunks).
    void draw(const FrameInputs& in, const FrameBlocks& blocks, DrawTechnique& technique) override;
    std::uint64_t gpu_bytes() const override { return std::uint64_t(capacity_) * 12 + std::uint64_t(kBuckets) * kLanes * 4; }

private:
    void ensure_buffers(std::uint32_t scene_chunks);
    void key_chunks(const FrameInputs& in, const FrameBlocks& blocks);
    void sort_chunks(std::uint32_t scene_chunks);
    void draw_sorted(const FrameInputs& in, const FrameBlocks& blocks, std::uint32_t chunks, DrawTechnique& technique);

    std::uint32_t chunks_per_block_ = 0;
    GlProgram keys_, count_, scan_, scatter_;
    GlBuffer chunk_keys_, histogram_, sorted_blocks_, sorted_chunks_;
    std::uint32_t capacity_ = 0;  // chunks: of the scene (keys), of a frame (sorted places)
};

}  // namespace fiblet::viewer
