#include "block_decoder.hpp"

#include <algorithm>

#include "gpu_bindings.hpp"
#include "shader_program.hpp"

namespace fiblet::viewer {

namespace {
// GL guarantees 65535 workgroups per dispatch dimension; 32768 blocks of 60
// points are 32 MB of points, well under every driver's storage limit.
constexpr std::uint32_t kMaxBatchBlocks = 32768;
constexpr std::uint32_t kPointBytes = 16;  // vec4
}  // namespace

BlockDecoder::BlockDecoder(const GpuPrograms& programs, std::uint32_t points_per_block)
    : programs_(programs), points_per_block_(points_per_block) {
    const std::uint64_t slot_bytes = std::uint64_t(points_per_block + 1) * kPointBytes;
    capacity_ = std::uint32_t(std::min<std::uint64_t>(kMaxBatchBlocks, max_storage_buffer_bytes() / slot_bytes));
    points_ = make_buffer(GLsizeiptr(capacity_ * slot_bytes), nullptr, 0);
}

void BlockDecoder::decode(const GpuScene& scene, bool use_list, std::uint32_t first, std::uint32_t count) const {
    if (count == 0) return;
    const GlProgram& p = programs_.decode;
    glUseProgram(p.get());
    scene.bind(p);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding::kPoints, points_.get());
    glProgramUniform1i(p.get(), uniform(p, "uUseList"), use_list ? 1 : 0);
    glProgramUniform1ui(p.get(), uniform(p, "uFirst"), first);
    glProgramUniform1i(p.get(), uniform(p, "uEndsOnly"), 0);
    glDispatchCompute(std::min(count, capacity_), 1, 1);
}

std::vector<float> decode_blocks_on_gpu(const GpuScene& scene, const GpuPrograms& programs, std::uint32_t first,
                                        std::uint32_t count) {
    const std::uint32_t ppb = scene.header().points_per_block;
    const BlockDecoder decoder(programs, ppb);
    std::vector<float> xyz;
    std::vector<float> slots;
    for (std::uint32_t done = 0; done < count;) {
        const std::uint32_t batch = std::min(decoder.capacity(), count - done);
        decoder.decode(scene, false, first + done, batch);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        slots.resize(std::size_t(batch) * (ppb + 1) * 4);
        glGetNamedBufferSubData(decoder.points_buffer(), 0, GLsizeiptr(slots.size() * 4), slots.data());
        for (std::uint32_t i = 0; i < batch; ++i) {
            const float* slot = &slots[std::size_t(i) * (ppb + 1) * 4];
            for (std::uint32_t k = 0; k < scene.block_points(first + done + i); ++k)
                xyz.insert(xyz.end(), {slot[4 * k], slot[4 * k + 1], slot[4 * k + 2]});
        }
        done += batch;
    }
    return xyz;
}

}  // namespace fiblet::viewer
