// Time of the frame's stages. A stage may be entered several times per frame
// (one decode and one draw per batch); its times are summed.
//   queries: GL timer queries (GL_TIME_ELAPSED), GPU time without stalls;
//   finish:  glFinish before and after each stage, CPU wall clock. For Mesa's
//            software renderers, whose timer queries do not measure the work
//            (llvmpipe runs compute at dispatch and rasterizes at flush).
#pragma once

#include <array>
#include <chrono>
#include <vector>

#include "gl/gl_objects.hpp"

namespace fiblet::viewer {

enum class Stage { cull = 0, decode = 1, draw = 2 };
enum class TimingMethod { none, queries, finish };

// queries, or finish on a Mesa software renderer (current context).
TimingMethod default_timing_method();
const char* timing_method_name(TimingMethod m);

class GpuTimer {
public:
    explicit GpuTimer(TimingMethod method) : method_(method) {}
    void begin(Stage s);
    void end();
    // Waits for the queries and returns milliseconds per stage.
    std::array<double, 3> collect();

private:
    TimingMethod method_;
    Stage current_ = Stage::cull;
    std::chrono::steady_clock::time_point started_;
    std::array<double, 3> finished_ms_{};
    std::vector<std::pair<Stage, GlQuery>> queries_;
};

}  // namespace fiblet::viewer
