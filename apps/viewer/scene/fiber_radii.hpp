// Per-fiber tube radii from a text file: one radius in mm per streamline,
// in file order (the format of fiber_colors.hpp's value files).
#pragma once

#include <string>

namespace fiblet::viewer {

class GpuScene;

// Throws fiblet::Error{io} when unreadable, {invalid_input} on a wrong
// count or a radius that is not a positive number.
void load_fiber_radii(const std::string& path, GpuScene& scene);

}  // namespace fiblet::viewer
