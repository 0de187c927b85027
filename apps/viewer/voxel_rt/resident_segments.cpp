#include "voxel_rt/resident_segments.hpp"

#include <algorithm>
#include <chrono>
#include <string>

#include "block_decoder.hpp"
#include "fiblet/error.hpp"

namespace fiblet::viewer::voxel_rt {

SceneSegments::SceneSegments(const GpuScene& scene, const GpuPrograms& programs)
    : scene_(&scene), slots_(scene.block_count()), per_slot_(scene.header().points_per_block) {
    const std::uint64_t slot_bytes = std::uint64_t(per_slot_ + 1) * 16;
    const std::uint64_t bytes = std::max<std::uint64_t>(slot_bytes * slots_, 16);
    if (bytes > max_storage_buffer_bytes())
        throw Error(Errc::unsupported, "voxel-rt: the decoded segments (" + std::to_string(bytes >> 20) +
                                           " MiB) exceed the driver's largest storage buffer (" +
                                           std::to_string(max_storage_buffer_bytes() >> 20) + " MiB)");
    points_ = make_buffer(GLsizeiptr(bytes), nullptr, 0);
    glFinish();
    const auto t0 = std::chrono::steady_clock::now();
    // Batches of the shared decoder, copied into place.
    const BlockDecoder decoder(programs, per_slot_);
    for (std::uint32_t first = 0; first < slots_; first += decoder.capacity()) {
        const std::uint32_t count = std::min(decoder.capacity(), slots_ - first);
        decoder.decode(scene, default_decoder(), false, first, count);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
        glCopyNamedBufferSubData(decoder.points_buffer(), points_.get(), 0, GLintptr(first * slot_bytes),
                                 GLsizeiptr(count * slot_bytes));
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    }
    glFinish();
    decode_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace fiblet::viewer::voxel_rt
