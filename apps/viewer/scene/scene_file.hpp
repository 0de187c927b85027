// Opening what the viewer draws: a .fft file as it is, or a .tck, .trk or
// TRX file compressed on the fly (into a temporary .fft, removed once open).
#pragma once

#include <string>

#include "fiblet/fft_file.hpp"
#include "fiblet_viewer/scene_sources.hpp"
#include "scene/fiber_streaming.hpp"
#include "scene/gpu_scene.hpp"

namespace fiblet::viewer {

// Throws fiblet::Error like FftFile / compress_file.
FftFile open_scene_file(const std::string& path);

// The first scene of `file`: every fiber, or the overview of a file beyond
// `streaming`'s budget, with the per-fiber colours (or point values), radii
// and opacities of the sources given (empty: none). Throws fiblet::Error as
// the scene and the sources' readers.
GpuScene first_scene(const FftFile& file, const GpuPrograms& programs, const FiberStreaming& streaming,
                     const FiberColorSource& colors, const std::string& radii_path, const std::string& opacity_source);

}  // namespace fiblet::viewer
