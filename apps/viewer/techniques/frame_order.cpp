#include "techniques/frame_order.hpp"

#include <algorithm>

#include "gl/gpu_bindings.hpp"

namespace fiblet::viewer {

void ListOrder::draw(const FrameInputs& in, const FrameBlocks& blocks, DrawTechnique& technique) {
    technique.begin_frame(in);
    const BlockDecoder& decoder = blocks.decoder;
    for (std::uint32_t first = 0; first < blocks.count; first += decoder.capacity()) {
        const std::uint32_t count = std::min<std::uint32_t>(decoder.capacity(), blocks.count - first);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kFineList, blocks.fine_list);
        blocks.timer.begin(Stage::decode);
        decoder.decode(in.scene, blocks.kind, in.use_list, first, count, technique.needs_tangents());
        blocks.timer.end();
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        blocks.timer.begin(Stage::draw);
        technique.draw_batch(in, {decoder.points_buffer(), decoder.tangents_buffer(), first, count});
        blocks.timer.end();
        // The next batch overwrites the points this draw reads.
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
}

}  // namespace fiblet::viewer
