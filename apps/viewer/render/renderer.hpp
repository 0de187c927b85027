// One frame: select blocks on the GPU (fiber subset, frustum culling, level
// of detail), decode the selected blocks on the GPU a batch at a time and
// hand each batch to the drawing style's technique (techniques/), then the
// coarse blocks (one segment each). With opacity < 1 the frame blends, in
// the order of transparency/ (RenderOptions::transparency). Everything stays
// on the GPU except four counters read back per frame (the list sizes,
// which size the batches and are shown to the user).
// Overlays (overlays/) follow the fibers in the same frame.
#pragma once

#include <memory>
#include <vector>

#include "scene/block_decoder.hpp"
#include "fiblet/view.hpp"
#include "gl/gl_objects.hpp"
#include "gl/gpu_bindings.hpp"
#include "scene/gpu_programs.hpp"
#include "scene/gpu_scene.hpp"
#include "overlays/color_bar/color_bar.hpp"
#include "overlays/overlay.hpp"
#include "gl/gpu_timer.hpp"
#include "fiblet_viewer/render_options.hpp"
#include "render/render_target.hpp"
#include "techniques/technique_registry.hpp"
#include "transparency/blend_target.hpp"
#include "voxel_rt/voxel_ray_tracer.hpp"

namespace fiblet::viewer {

class Renderer {
public:
    explicit Renderer(const GpuPrograms& programs);

    // Draws with options.engine: the raster pipeline below, or the voxel
    // ray tracer (voxel_rt/), which does its own selection and decoding.
    FrameStats render(const GpuScene& scene, const Camera& camera, const RenderOptions& options,
                      RenderTarget& target);

    // How far (mm) what `options` draws reaches beyond the fibers' centre
    // lines (a tube's radius): what views test blocks with.
    float reach_mm(const GpuScene& scene, const RenderOptions& options);

    // The voxel ray tracer render() uses (made on first use; tests).
    voxel_rt::VoxelRayTracer& voxel_ray_tracer();
    const voxel_rt::VoxelRayTracer* voxel_ray_tracer_if_made() const { return voxel_ray_tracer_.get(); }

    // The selection pass alone (what render() runs first when culling, LoD
    // or a subset is on): fills the fine and coarse lists and returns their
    // sizes.
    DrawCounters select_blocks(const GpuScene& scene, const Camera& camera, const Viewport& viewport,
                               const RenderOptions& options);

    // Draws `style` with `technique` from now on instead of its default
    // module (tests: a technique built with other parameters).
    void use_technique(DrawStyle style, std::unique_ptr<DrawTechnique> technique) {
        techniques_.replace(style, std::move(technique));
    }

    // Overlays (glyphs, image slices) drawn after the fibers of every frame,
    // in this order, with depth.
    void set_overlays(std::vector<std::shared_ptr<Overlay>> overlays) { overlays_ = std::move(overlays); }
    // GPU memory held for transparency (blend image, sort buffers, voxlines).
    std::uint64_t transparency_bytes() const;

    // Each block's decision in the last selection pass run with
    // options.record_decisions.
    std::vector<BlockDecision> read_decisions(const GpuScene& scene) const;

private:
    void ensure_buffers(const GpuScene& scene, bool decisions);

    const GpuPrograms& programs_;
    std::unique_ptr<voxel_rt::VoxelRayTracer> voxel_ray_tracer_;  // made on first use
    std::unique_ptr<BlockDecoder> decoder_;
    TechniqueRegistry techniques_;
    GlBuffer fine_list_, coarse_list_, counters_, decisions_;
    std::uint32_t list_capacity_ = 0, decisions_capacity_ = 0;
    std::vector<std::shared_ptr<Overlay>> overlays_;
    GlVertexArray empty_vertex_array_;  // core profile draws need one bound
    BlendTarget blend_target_;             // transparent frames (transparency/)
    std::unique_ptr<ColorBar> color_bar_;  // made when a frame first shows one
};

}  // namespace fiblet::viewer
