#include "voxel_rt/resident_segments.hpp"

#include <algorithm>
#include <chrono>
#include <string>

#include "scene/block_decoder.hpp"
#include "fiblet/error.hpp"
#include "voxel_rt/voxel_rt_bindings.hpp"

namespace fiblet::viewer::voxel_rt {

SceneSegments::SceneSegments(const GpuScene& scene, const GpuPrograms& programs, std::uint64_t part_bytes)
    : scene_(&scene), slots_(scene.block_count()), per_slot_(scene.header().points_per_block) {
    const std::uint64_t slot_bytes = std::uint64_t(per_slot_ + 1) * 16;
    const std::uint64_t limit = part_bytes ? std::min(part_bytes, max_storage_buffer_bytes()) : max_storage_buffer_bytes();
    const std::uint64_t per_part = std::max<std::uint64_t>(limit / slot_bytes, 1);
    const std::uint64_t parts = std::max<std::uint64_t>((std::uint64_t(slots_) + per_part - 1) / per_part, 1);
    bytes_ = slot_bytes * slots_;
    if (parts > binding::kPointParts)
        throw Error(Errc::unsupported, "voxel-rt: the decoded segments (" + std::to_string(bytes_ >> 20) +
                                           " MiB) exceed " + std::to_string(binding::kPointParts) +
                                           " of the driver's largest storage buffers (" +
                                           std::to_string(limit >> 20) + " MiB each)");
    slots_per_part_ = std::uint32_t(std::min<std::uint64_t>(per_part, std::max(slots_, 1u)));
    for (std::uint64_t part = 0; part < parts; ++part) {
        const std::uint64_t first = part * slots_per_part_;
        const std::uint64_t count = std::min<std::uint64_t>(slots_per_part_, slots_ - std::min<std::uint64_t>(first, slots_));
        parts_.push_back(make_buffer(GLsizeiptr(std::max<std::uint64_t>(count * slot_bytes, 16)), nullptr, 0));
    }
    glFinish();
    const auto t0 = std::chrono::steady_clock::now();
    // Batches of the shared decoder, copied into place (a batch never
    // straddles two parts).
    const BlockDecoder decoder(programs, per_slot_);
    for (std::uint32_t first = 0; first < slots_;) {
        const std::uint32_t part = first / slots_per_part_, in_part = first - part * slots_per_part_;
        const std::uint32_t count = std::min({decoder.capacity(), slots_ - first, slots_per_part_ - in_part});
        decoder.decode(scene, default_decoder(), false, first, count);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
        glCopyNamedBufferSubData(decoder.points_buffer(), parts_[part].get(), 0, GLintptr(in_part * slot_bytes),
                                 GLsizeiptr(count * slot_bytes));
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        first += count;
    }
    glFinish();
    decode_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

ResidentSegments SceneSegments::segments() const {
    ResidentSegments s{parts_[0].get(), slots_, per_slot_, scene_};
    if (parts_.size() > 1) {
        for (std::size_t k = 1; k < parts_.size(); ++k) s.more_parts.push_back(parts_[k].get());
        s.slots_per_part = slots_per_part_;
    }
    return s;
}

}  // namespace fiblet::viewer::voxel_rt
