// A file beyond the GPU memory budget in the window (scene/fiber_streaming.hpp):
// the sparse overview is drawn while the view moves, and once a view has
// rested for kRestSeconds the fibers it sees are loaded and drawn instead.
#pragma once

#include <chrono>
#include <optional>

#include "fiblet/fft_file.hpp"
#include "fiblet/view.hpp"
#include "scene/fiber_streaming.hpp"
#include "scene/gpu_scene.hpp"

namespace fiblet::viewer {

class StreamedView {
public:
    static constexpr double kRestSeconds = 0.3;

    // `overview` holds the streaming's overview (or, when the file fits,
    // every fiber: then it is always the scene drawn).
    StreamedView(GpuScene& overview, const FftFile& file, const GpuPrograms& programs, const FiberStreaming& streaming,
                 std::chrono::steady_clock::time_point opened);

    // The scene to draw `camera` with: the view's fibers when they were
    // loaded for it, else the overview. Loads them first when the view has
    // rested long enough; `loaded` says so (the frame must be drawn again).
    const GpuScene& scene_for(const Camera& camera, float margin_mm, bool& loaded);
    // A view is resting towards a load: poll for events often.
    bool load_pending() const { return streaming_.streams() && pending_; }
    std::uint64_t gpu_bytes() const;

private:
    GpuScene& overview_;
    const FftFile& file_;
    const GpuPrograms& programs_;
    const FiberStreaming& streaming_;
    std::chrono::steady_clock::time_point opened_;
    std::optional<GpuScene> detail_;
    std::optional<Camera> detail_for_, last_;
    std::chrono::steady_clock::time_point last_change_{};
    bool pending_ = true;
};

double seconds_since(std::chrono::steady_clock::time_point start);

}  // namespace fiblet::viewer
