#include "window/streamed_view.hpp"

#include <fmt/core.h>

#include <cstdio>

namespace fiblet::viewer {

namespace {

bool same_view(const Camera& a, const Camera& b) {
    auto same = [](Vec3f p, Vec3f q) { return p.x == q.x && p.y == q.y && p.z == q.z; };
    return same(a.position, b.position) && same(a.target, b.target) && same(a.up, b.up) && a.fov_y_deg == b.fov_y_deg &&
           a.aspect == b.aspect;
}

}  // namespace

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

StreamedView::StreamedView(GpuScene& overview, const FftFile& file, const GpuPrograms& programs,
                           const FiberStreaming& streaming, std::chrono::steady_clock::time_point opened)
    : overview_(overview), file_(file), programs_(programs), streaming_(streaming), opened_(opened) {}

const GpuScene& StreamedView::scene_for(const Camera& camera, float margin_mm, bool& loaded) {
    loaded = false;
    if (!streaming_.streams()) return overview_;
    if (!last_ || !same_view(*last_, camera)) last_ = camera, last_change_ = std::chrono::steady_clock::now();
    const bool current = detail_for_ && same_view(*detail_for_, camera);
    pending_ = !current;
    if (current) return *detail_;
    if (seconds_since(last_change_) < kRestSeconds) return overview_;

    const auto start = std::chrono::steady_clock::now();
    hold_view(detail_, overview_, file_, programs_, streaming_, camera, margin_mm);
    detail_for_ = camera, pending_ = false, loaded = true;
    fmt::print("holding the view's {} of {} fibers ({} blocks, {:.1f} MB) in {:.2f} s ({:.2f} s after opening)\n",
               detail_->fiber_count(), detail_->file_fiber_count(), detail_->block_count(), detail_->gpu_bytes() / 1e6,
               seconds_since(start), seconds_since(opened_));
    std::fflush(stdout);
    return *detail_;
}

std::uint64_t StreamedView::gpu_bytes() const { return overview_.gpu_bytes() + (detail_ ? detail_->gpu_bytes() : 0); }

}  // namespace fiblet::viewer
