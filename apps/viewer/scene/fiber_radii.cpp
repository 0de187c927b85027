#include "scene/fiber_radii.hpp"

#include <fmt/core.h>

#include "scene/fiber_colors.hpp"
#include "fiblet/error.hpp"
#include "scene/gpu_scene.hpp"

namespace fiblet::viewer {

void load_fiber_radii(const std::string& path, GpuScene& scene) {
    const std::vector<float> radii = read_fiber_values(path, scene.file_fiber_count());
    for (std::size_t i = 0; i < radii.size(); ++i)
        if (!(radii[i] > 0))
            throw Error(Errc::invalid_input, fmt::format("{}: radius {} of streamline {} is not positive", path, radii[i], i));
    scene.set_fiber_radii(radii);
}

}  // namespace fiblet::viewer
