#include "scene/fiber_opacity.hpp"

#include <fmt/core.h>

#include "scene/fiber_colors.hpp"
#include "fiblet/error.hpp"
#include "scene/gpu_scene.hpp"

namespace fiblet::viewer {

void load_fiber_opacities(const std::string& source, const FftFile& file, GpuScene& scene) {
    const std::vector<float> alpha = read_fiber_value_source(source, file);
    for (std::size_t i = 0; i < alpha.size(); ++i)
        if (!(alpha[i] >= 0 && alpha[i] <= 1))
            throw Error(Errc::invalid_input,
                        fmt::format("{}: opacity {} of streamline {} is not in [0, 1]", source, alpha[i], i));
    scene.set_fiber_opacities(alpha);
}

}  // namespace fiblet::viewer
