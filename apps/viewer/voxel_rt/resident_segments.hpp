// Every block of a scene decoded once on the GPU (the voxel ray tracer needs
// all segments resident: its fragment lists point into them). The layout
// is BlockDecoder's slots, block b in slot b, split over up to
// binding::kPointParts storage buffers of whole slots when one buffer
// cannot hold them all.
//
// Memory: (points per block + 1) × 16 bytes per block (976 B for 60 points,
// ≈ 16.3 B per segment), in parts of at most the driver's largest storage
// buffer (llvmpipe: 128 MiB, ≈ 137 k blocks, 8 M segments per part; eight
// parts: 1 GiB, ≈ 66 M segments). A file needing more parts is refused with
// fiblet::Error{unsupported} rather than drawn in part.
#pragma once

#include <cstdint>
#include <vector>

#include "gl/gl_objects.hpp"
#include "scene/gpu_programs.hpp"
#include "scene/gpu_scene.hpp"
#include "voxel_rt/voxel_structure.hpp"

namespace fiblet::viewer::voxel_rt {

class SceneSegments {
public:
    // part_bytes: the most bytes of one part (0: the driver's largest
    // storage buffer; tests set a few MB to force the split).
    SceneSegments(const GpuScene& scene, const GpuPrograms& programs, std::uint64_t part_bytes = 0);
    ResidentSegments segments() const;
    double decode_ms() const { return decode_ms_; }
    std::size_t part_count() const { return parts_.size(); }
    std::uint64_t bytes() const { return bytes_; }

private:
    const GpuScene* scene_;
    std::vector<GlBuffer> parts_;
    std::uint32_t slots_ = 0, per_slot_ = 1, slots_per_part_ = 0;
    std::uint64_t bytes_ = 0;
    double decode_ms_ = 0;
};

}  // namespace fiblet::viewer::voxel_rt
