// An OpenGL 4.5 core context without a window, through EGL: the device
// platform (any GPU, or Mesa's software device) first, then Mesa's
// surfaceless platform. Works with Mesa's llvmpipe on machines without a GPU.
#pragma once

#include <memory>
#include <string>

namespace fiblet::viewer {

class HeadlessContext {
public:
    // Creates the context and makes it current on this thread. Throws
    // fiblet::Error{unsupported} naming what failed (no EGL display, no GL 4.5).
    HeadlessContext();
    ~HeadlessContext();
    HeadlessContext(const HeadlessContext&) = delete;
    HeadlessContext& operator=(const HeadlessContext&) = delete;

    // "renderer, GL version" as the driver reports them.
    const std::string& description() const { return description_; }

private:
    struct State;
    std::unique_ptr<State> state_;
    std::string description_;
};

}  // namespace fiblet::viewer
