// The voxel ray tracing engine (Kraaijeveld et al., "Real-Time Rendering of
// Dynamic Line Sets using Voxel Ray Tracing", CGF 2026) on the GPU
// decoder's output: every segment is a capsule of RenderOptions::
// tube_radius_mm. Unlike the per-batch techniques it needs all segments
// resident and a voxelization before the first pixel; both are kept
// between frames while the scene, grid, radius and ambient occlusion stay
// the same (the lines are static here), so a frame is one full-screen trace.
#pragma once

#include <memory>

#include "scene/gpu_programs.hpp"
#include "scene/gpu_scene.hpp"
#include "fiblet_viewer/render_options.hpp"
#include "render/render_target.hpp"
#include "voxel_rt/chord_occlusion.hpp"
#include "voxel_rt/resident_segments.hpp"
#include "voxel_rt/voxel_culling.hpp"
#include "voxel_rt/voxel_rt_programs.hpp"
#include "voxel_rt/voxel_structure.hpp"

namespace fiblet::viewer::voxel_rt {

class VoxelRayTracer {
public:
    explicit VoxelRayTracer(const GpuPrograms& programs);
    ~VoxelRayTracer();

    // Draws the frame (clearing the target when options.clear). The first
    // frame of a scene decodes and voxelizes it: its FrameStats::decode_ms
    // holds that preprocessing, draw_ms the trace (with time_stages).
    FrameStats render(const GpuScene& scene, const Camera& camera, const RenderOptions& options,
                      RenderTarget& target);

    // The chord-based ambient occlusion of the scene on options' grid, for
    // the rasterized styles' --ao (built on first use, kept while the scene,
    // grid and radius stay the same).
    OcclusionVolume chord_occlusion(const GpuScene& scene, const RenderOptions& options);
    const ChordOcclusion* chord_occlusion_structure() const { return chords_.get(); }

    // Tests: the fiber buffer gets segment + 1 (segment s = block ×
    // points_per_block + its index in the block) instead of fiber + 1.
    void write_segment_ids(bool on) { write_segment_ids_ = on; }
    // The structure the last frame traced (null before the first).
    const VoxelStructure* structure() const { return structure_.get(); }
    // The culling of the last opaque frame with culling on (null before).
    const VoxelCulling* culling() const { return culling_.get(); }
    double last_decode_ms() const { return segments_ ? segments_->decode_ms() : 0; }
    // The most bytes of one buffer of resident segments and of one buffer of
    // fragment lists (0: the driver's largest storage buffer and buffer
    // texture; tests set a few MB to force the split over several buffers).
    // Takes effect with the next scene built.
    void set_segment_part_bytes(std::uint64_t bytes) { part_bytes_ = bytes, segments_.reset(); }
    // Storage buffers the resident segments of the last frame occupy.
    std::size_t segment_parts() const { return segments_ ? segments_->part_count() : 0; }
    std::size_t fragment_parts() const { return structure_ ? structure_->fragment_parts() : 0; }

private:
    void ensure_structure(const GpuScene& scene, const RenderOptions& options);
    void trace(const Camera& camera, const RenderOptions& options, RenderTarget& target);
    ResidentSegments segments_for(const GpuScene& scene, const RenderOptions& options) const;

    const GpuPrograms& shared_;
    VoxelRtPrograms programs_;
    std::unique_ptr<SceneSegments> segments_;
    std::unique_ptr<VoxelStructure> structure_;
    std::unique_ptr<VoxelCulling> culling_;  // of structure_
    const GpuScene* built_scene_ = nullptr;
    std::uint64_t built_generation_ = 0;  // GpuScene::generation()
    int built_grid_ = 0;
    float built_radius_ = 0;
    bool built_fiber_radii_ = false;
    std::unique_ptr<ChordOcclusion> chords_;
    std::uint64_t chords_scene_ = 0;
    int chords_grid_ = 0;
    float chords_radius_ = 0;
    GlVertexArray empty_vertex_array_;
    bool write_segment_ids_ = false;
    std::uint64_t part_bytes_ = 0;
};

}  // namespace fiblet::viewer::voxel_rt
