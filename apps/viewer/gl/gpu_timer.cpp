#include "gl/gpu_timer.hpp"

#include "gl/gl_info.hpp"

namespace fiblet::viewer {

TimingMethod default_timing_method() { return is_software_renderer() ? TimingMethod::finish : TimingMethod::queries; }

const char* timing_method_name(TimingMethod m) {
    switch (m) {
        case TimingMethod::none: return "none";
        case TimingMethod::queries: return "GL timer queries";
        case TimingMethod::finish: return "glFinish + wall clock";
    }
    return "?";
}

void GpuTimer::begin(Stage s) {
    current_ = s;
    if (method_ == TimingMethod::finish) {
        glFinish();
        started_ = std::chrono::steady_clock::now();
    } else if (method_ == TimingMethod::queries) {
        GLuint q = 0;
        glCreateQueries(GL_TIME_ELAPSED, 1, &q);
        queries_.emplace_back(s, GlQuery(q));
        glBeginQuery(GL_TIME_ELAPSED, q);
    }
}

void GpuTimer::end() {
    if (method_ == TimingMethod::finish) {
        glFinish();
        finished_ms_[std::size_t(current_)] +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started_).count();
    } else if (method_ == TimingMethod::queries) {
        glEndQuery(GL_TIME_ELAPSED);
    }
}

std::array<double, 3> GpuTimer::collect() {
    std::array<double, 3> ms = finished_ms_;
    for (const auto& [stage, query] : queries_) {
        GLuint64 ns = 0;
        glGetQueryObjectui64v(query.get(), GL_QUERY_RESULT, &ns);
        ms[std::size_t(stage)] += double(ns) * 1e-6;
    }
    queries_.clear();
    finished_ms_ = {};
    return ms;
}

}  // namespace fiblet::viewer
