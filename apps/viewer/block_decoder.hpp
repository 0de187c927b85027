// Runs the GPU decoder (decode_blocks.comp.glsl) on batches of blocks into a
// points buffer of fixed capacity: the renderer decodes a batch, draws it,
// and reuses the buffer for the next one, so the memory used does not grow
// with the file.
#pragma once

#include <cstdint>
#include <vector>

#include "gl_objects.hpp"
#include "gpu_programs.hpp"
#include "gpu_scene.hpp"

namespace fiblet::viewer {

class BlockDecoder {
public:
    BlockDecoder(const GpuPrograms& programs, std::uint32_t points_per_block);

    std::uint32_t points_per_block() const { return points_per_block_; }
    std::uint32_t capacity() const { return capacity_; }  // blocks per batch
    GLuint points_buffer() const { return points_.get(); }

    // Decodes `count` (<= capacity) blocks into slots 0..count-1 of the
    // points buffer: blocks list[first + i] of the list bound at
    // binding::kFineList when `use_list`, else blocks first + i. Slot i holds
    // points_per_block + 1 vec4 (world mm): the block's points, then the
    // first point of the next block of its fiber.
    void decode(const GpuScene& scene, bool use_list, std::uint32_t first, std::uint32_t count) const;

private:
    const GpuPrograms& programs_;
    std::uint32_t points_per_block_, capacity_;
    GlBuffer points_;
};

// Decodes blocks [first, first + count) of the scene on the GPU and reads
// the points back: xyz world mm, the blocks' points one after the other (the
// layout of fiblet::decode_blocks_scalar). For tests and tools.
std::vector<float> decode_blocks_on_gpu(const GpuScene& scene, const GpuPrograms& programs, std::uint32_t first,
                                        std::uint32_t count);

}  // namespace fiblet::viewer
