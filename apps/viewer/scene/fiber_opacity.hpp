// Per-fiber opacities (--fiber-opacity): one value in [0, 1] per streamline,
// in file order, from a text file or the .fft's own per-streamline data
// ("dps/NAME"), as --fiber-values reads them (fiber_colors.hpp). They
// multiply the global opacity (RenderOptions::fiber_opacity).
#pragma once

#include <string>

namespace fiblet {
class FftFile;
}

namespace fiblet::viewer {

class GpuScene;

// Throws fiblet::Error{io} when the file is unreadable, {invalid_argument}
// for a dps name the file does not carry, {invalid_input} on a wrong count
// or a value outside [0, 1].
void load_fiber_opacities(const std::string& source, const FftFile& file, GpuScene& scene);

}  // namespace fiblet::viewer
