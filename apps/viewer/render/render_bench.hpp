// The frame-time benchmark of `fiblet render --bench`: the same scene drawn
// from several distances, with and without the GPU selection (frustum
// culling + level of detail), timed per stage with GL timer queries.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "fiblet/view.hpp"
#include "scene/block_decoder.hpp"
#include "scene/gpu_scene.hpp"
#include "fiblet_viewer/headless_render.hpp"
#include "fiblet_viewer/render_options.hpp"
#include "render/renderer.hpp"

namespace fiblet::viewer {

// The benchmark's views, nearest last but one: the whole scene; a close-up
// where about a third of the blocks are off-screen; far away.
inline const char* const kBenchViews[] = {"overview", "close-up", "far"};

// `camera_for(zoom)` places the camera (zoom 1 = the whole scene). Runs one
// warm-up frame then `frames` timed frames per case: each of `views` (names
// of kBenchViews) with and without culling + LoD.
std::vector<BenchCase> run_render_bench(const GpuScene& scene, Renderer& renderer, RenderTarget& target,
                                        const std::function<Camera(float zoom)>& camera_for,
                                        const RenderOptions& base, int frames, const std::vector<std::string>& views);

// A transparent frame against the opaque one (the overview, culling on):
// median wall times of both, and the GPU memory transparency added.
TransparencyBench run_transparency_bench(const GpuScene& scene, Renderer& renderer, RenderTarget& target,
                                         const Camera& camera, const RenderOptions& transparent, int frames);

// Median time (ms) to decode every block of the scene with `kind`, in
// batches as the renderer does, without drawing.
double time_full_decode(const GpuScene& scene, const GpuPrograms& programs, GpuDecoder kind, int frames);

}  // namespace fiblet::viewer
