// Runs a GPU decoder on batches of blocks into a points buffer of fixed
// capacity: the renderer decodes a batch, draws it, and reuses the buffer for
// the next one, so the memory used does not grow with the file.
#pragma once

#include <cstdint>
#include <vector>

#include "fiblet_viewer/gpu_decoder.hpp"
#include "gl/gl_objects.hpp"
#include "scene/gpu_programs.hpp"
#include "scene/gpu_scene.hpp"

namespace fiblet::viewer {

// scan, or sequential on a software renderer (current context).
GpuDecoder default_decoder();

// One decode pass over `count` blocks: list[first + i] of the list bound at
// binding::kFineList when `use_list`, else blocks first + i. With
// `ends_only`, writes only each block's last point to its fiber's entry of the
// fiber ends (the blocks must be last blocks of their fibers); otherwise
// writes slot i of the points buffer bound at binding::kPoints (at most 65535
// blocks per pass), and with `tangents` also slot i of the tangents buffer
// bound at binding::kTangents (decode_common.glsl says which tangent).
void dispatch_decode(const GpuPrograms& programs, GpuDecoder kind, const GpuScene& scene, bool use_list,
                     std::uint32_t first, std::uint32_t count, bool ends_only, bool tangents = false);

class BlockDecoder {
public:
    BlockDecoder(const GpuPrograms& programs, std::uint32_t points_per_block);

    std::uint32_t points_per_block() const { return points_per_block_; }
    std::uint32_t capacity() const { return capacity_; }  // blocks per batch
    GLuint points_buffer() const { return points_.get(); }
    // Allocated by the first decode that asks for tangents (0 before).
    GLuint tangents_buffer() const { return tangents_.get(); }

    // Decodes `count` (<= capacity) blocks (as dispatch_decode) into slots
    // 0..count-1 of the points buffer. Slot i holds points_per_block + 1
    // vec4 (world mm): the block's points, then the first point of the next
    // block of its fiber. With `tangents`, the tangents buffer gets each
    // point's unit tangent in the same layout.
    void decode(const GpuScene& scene, GpuDecoder kind, bool use_list, std::uint32_t first,
                std::uint32_t count, bool tangents = false) const;

private:
    const GpuPrograms& programs_;
    std::uint32_t points_per_block_, capacity_;
    GlBuffer points_;
    mutable GlBuffer tangents_;
};

// Decodes blocks [first, first + count) of the scene on the GPU and reads
// the points back: xyz world mm, the blocks' points one after the other (the
// layout of fiblet::decode_blocks_scalar). For tests and tools.
std::vector<float> decode_blocks_on_gpu(const GpuScene& scene, const GpuPrograms& programs, GpuDecoder kind,
                                        std::uint32_t first, std::uint32_t count);
// The same blocks' unit tangents (xyz, same layout).
std::vector<float> decode_tangents_on_gpu(const GpuScene& scene, const GpuPrograms& programs, GpuDecoder kind,
                                          std::uint32_t first, std::uint32_t count);

}  // namespace fiblet::viewer
