// Anti-aliased frames for screenshots and figures: the frame drawn at
// `factor` times the size (lines `factor` times as wide) and each
// factor × factor block of pixels averaged.
#pragma once

#include "scene/gpu_scene.hpp"
#include "gl/png_file.hpp"
#include "render/renderer.hpp"

namespace fiblet::viewer {

// The mean of each factor × factor block (width and height multiples of factor).
RgbaImage downsample_box(const RgbaImage& image, int factor);

struct SupersampledFrame {
    RgbaImage image;
    FrameStats stats;  // of the enlarged frame
};

// One frame of width × height pixels, supersampled `factor` times per axis
// (1: a plain render). Throws fiblet::Error{invalid_argument} when the
// factor is outside 1..kMaxSupersample or the enlarged frame exceeds the
// driver's largest render target.
SupersampledFrame render_supersampled(Renderer& renderer, const GpuScene& scene, const Camera& camera,
                              const RenderOptions& options, int width, int height, int factor);

}  // namespace fiblet::viewer
