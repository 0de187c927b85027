// What the ray tracer traces: from resident segments, the voxels' packed
// occupancy and counts (first voxelization pass), their fragment lists
// (prefix sum, second pass), the occupancy mip pyramids (averaged for the
// cones, "anything here" for empty-space skipping) and, on request, the
// ambient occlusion volume. Built once per scene, grid and radius: the
// frames only trace it.
#pragma once

#include <cstdint>
#include <vector>

#include "gl/gl_objects.hpp"
#include "scene/gpu_scene.hpp"
#include "voxel_rt/voxel_grid.hpp"
#include "voxel_rt/voxel_pyramid.hpp"
#include "voxel_rt/voxel_rt_programs.hpp"

namespace fiblet::viewer::voxel_rt {

// Segments resident on the GPU: `slots` slots of segments_per_slot + 1
// points (vec4, world mm) each, segment s joining points s + slot and
// s + slot + 1 (slot = s / segments_per_slot). With a scene, slot b is
// block b and holds blockSegmentCount(b) segments; without, every slot
// holds segments_per_slot.
// The points may be split over several storage buffers (parts, at most
// binding::kPointParts): then `points` is part 0, more_parts the others, and
// every part but the last holds slots_per_part whole slots.
struct ResidentSegments {
    GLuint points = 0;
    std::uint32_t slots = 0, segments_per_slot = 1;
    const GpuScene* scene = nullptr;
    std::vector<GLuint> more_parts;
    std::uint32_t slots_per_part = 0;  // with more_parts
    // Capsules of the scene's per-fiber radii instead of radius_mm (with a
    // scene that has them).
    bool fiber_radii = false;
};

struct BuildTimes {
    double count_ms = 0, scan_ms = 0, fill_ms = 0, occupancy_ms = 0, ambient_occlusion_ms = 0;
    double total_ms() const { return count_ms + scan_ms + fill_ms + occupancy_ms + ambient_occlusion_ms; }
};

// Sets the uniforms of voxel_segments.glsl (and the scene's) on `program`
// and binds the segments.
void bind_segments(const GlProgram& program, const ResidentSegments& segments, const VoxelGrid& grid,
                   float radius_mm);

class VoxelStructure {
public:
    // The fragment lists lie in up to binding::kFragmentParts buffers of at
    // most part_bytes (0: GL_MAX_TEXTURE_BUFFER_SIZE texels; tests set a few
    // MB to force the split). Throws fiblet::Error{unsupported} when they
    // need more.
    VoxelStructure(const VoxelRtPrograms& programs, const VoxelGrid& grid, const ResidentSegments& segments,
                   float radius_mm, bool ambient_occlusion, std::uint64_t part_bytes = 0);

    const VoxelGrid& grid() const { return grid_; }
    const BuildTimes& times() const { return times_; }
    std::uint64_t fragment_count() const { return fragments_count_; }
    bool has_ambient_occlusion() const { return bool(ambient_occlusion_); }
    GLuint ambient_occlusion_texture() const { return ambient_occlusion_.get(); }
    GLuint cells_buffer() const { return cells_.get(); }
    // The layout of the grid's pyramids (the occupancy one here, the culling's).
    const PyramidLayout& pyramid() const { return pyramid_; }

    // Binds the cells and offsets buffers and the textures (occupancy on
    // unit 0, ambient occlusion on unit 1, the fragment lists' parts from
    // binding::kFragmentUnit, the occupancy pyramid on
    // binding::kOccupiedUnit), and sets `trace`'s uFragmentsPerPart and
    // pyramid layout.
    void bind(const GlProgram* trace = nullptr) const;
    std::size_t fragment_parts() const { return fragment_textures_.size(); }

    // Per voxel (x fastest): packed cell (occupancy << 16 | count).
    std::vector<std::uint32_t> read_cells() const;
    // The occupancy pyramid's levels 1.. (pyramid() layout, less level 1's
    // offset): 1 where a cell holds anything.
    std::vector<std::uint8_t> read_occupied_pyramid() const;
    // Per voxel: ambient occlusion in [0, 1] (empty without it).
    std::vector<float> read_ambient_occlusion() const;

private:
    void count_and_occupy(const VoxelRtPrograms& p, const ResidentSegments& s, float radius_mm);
    void prefix_sum(const VoxelRtPrograms& p);
    void fill_lists(const VoxelRtPrograms& p, const ResidentSegments& s, float radius_mm);
    void build_occupancy(const VoxelRtPrograms& p);
    void build_occupied_pyramid(const VoxelRtPrograms& p);
    void build_ambient_occlusion(const VoxelRtPrograms& p);
    void dispatch_segments(const GlProgram& program, const ResidentSegments& s) const;

    VoxelGrid grid_;
    BuildTimes times_;
    GlBuffer cells_, offsets_, cursor_;
    std::vector<GlBuffer> fragment_parts_;
    std::vector<GlTexture> fragment_textures_;  // R32UI buffer textures of fragment_parts_
    std::uint32_t fragments_per_part_ = 1;
    std::uint64_t part_bytes_ = 0;
    GlTexture occupancy_, ambient_occlusion_;
    PyramidLayout pyramid_;
    GlBuffer occupied_;             // levels 1.. of the occupancy pyramid, one byte a cell
    GlTexture occupied_texture_;    // R8UI buffer texture of occupied_
    std::uint64_t fragments_count_ = 0;
};

}  // namespace fiblet::viewer::voxel_rt
