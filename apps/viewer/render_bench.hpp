// The frame-time benchmark of `fiblet render --bench`: the same scene drawn
// from several distances, with and without the GPU selection (frustum
// culling + level of detail), timed per stage with GL timer queries.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "fiblet/view.hpp"
#include "gpu_scene.hpp"
#include "render_options.hpp"
#include "renderer.hpp"

namespace fiblet::viewer {

struct BenchCase {
    std::string view;   // "overview", "close-up", "far"
    bool selection;     // frustum culling + level of detail on
    FrameStats median;  // stage times: medians over the frames; counts of the last frame
    double frame_ms;    // median wall time of a whole frame, glFinish included
};

// `camera_for(zoom)` places the camera (zoom 1 = the whole scene). Runs one
// warm-up frame then `frames` timed frames per case.
std::vector<BenchCase> run_render_bench(const GpuScene& scene, Renderer& renderer, RenderTarget& target,
                                        const std::function<Camera(float zoom)>& camera_for,
                                        const RenderOptions& base, int frames);

}  // namespace fiblet::viewer
