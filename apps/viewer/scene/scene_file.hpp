// Opening what the viewer draws: a .fft file as it is, or a .tck, .trk or
// TRX file compressed on the fly (into a temporary .fft, removed once open).
#pragma once

#include <string>

#include "fiblet/fft_file.hpp"

namespace fiblet::viewer {

// Throws fiblet::Error like FftFile / compress_file.
FftFile open_scene_file(const std::string& path);

}  // namespace fiblet::viewer
