#include "gl/headless_context.hpp"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <string>
#include <vector>

#include "fiblet/error.hpp"
#include "gl/gl_info.hpp"

namespace fiblet::viewer {

struct HeadlessContext::State {
    EGLDisplay display = EGL_NO_DISPLAY;
    EGLContext context = EGL_NO_CONTEXT;
};

namespace {

bool has_client_extension(const char* name) { return epoxy_has_egl_extension(EGL_NO_DISPLAY, name); }

// Candidate displays, best first: every EGL device, then surfaceless Mesa.
std::vector<EGLDisplay> candidate_displays() {
    std::vector<EGLDisplay> out;
    if (has_client_extension("EGL_EXT_platform_device") && has_client_extension("EGL_EXT_device_enumeration")) {
        EGLint count = 0;
        if (eglQueryDevicesEXT(0, nullptr, &count) && count > 0) {
            std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(count));
            eglQueryDevicesEXT(count, devices.data(), &count);
            for (EGLint i = 0; i < count; ++i) {
                EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[std::size_t(i)], nullptr);
                if (d != EGL_NO_DISPLAY) out.push_back(d);
            }
        }
    }
    if (has_client_extension("EGL_MESA_platform_surfaceless")) {
        EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        if (d != EGL_NO_DISPLAY) out.push_back(d);
    }
    return out;
}

// A GL 4.5 core context on `d` without a surface, or EGL_NO_CONTEXT.
EGLContext try_context(EGLDisplay d) {
    EGLint major = 0, minor = 0;
    if (!eglInitialize(d, &major, &minor)) return EGL_NO_CONTEXT;
    if (!epoxy_has_egl_extension(d, "EGL_KHR_surfaceless_context") ||
        !epoxy_has_egl_extension(d, "EGL_KHR_no_config_context") || !eglBindAPI(EGL_OPENGL_API)) {
        eglTerminate(d);
        return EGL_NO_CONTEXT;
    }
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext c = eglCreateContext(d, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
    if (c == EGL_NO_CONTEXT) {
        eglTerminate(d);
        return EGL_NO_CONTEXT;
    }
    if (!eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, c)) {
        eglDestroyContext(d, c);
        eglTerminate(d);
        return EGL_NO_CONTEXT;
    }
    return c;
}

}  // namespace

HeadlessContext::HeadlessContext() : state_(std::make_unique<State>()) {
    for (EGLDisplay d : candidate_displays()) {
        EGLContext c = try_context(d);
        if (c == EGL_NO_CONTEXT) continue;
        state_->display = d, state_->context = c;
        break;
    }
    if (state_->context == EGL_NO_CONTEXT)
        throw Error(Errc::unsupported,
                    "cannot create a headless OpenGL 4.5 context through EGL (install libegl-mesa0 and "
                    "libgl1-mesa-dri for Mesa's software renderer)");
    // The context was created for version 4.5 core, so it is one.
    description_ = current_gl_description();
}

HeadlessContext::~HeadlessContext() {
    if (state_->context != EGL_NO_CONTEXT) {
        eglMakeCurrent(state_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(state_->display, state_->context);
        // No eglTerminate: it would unload the driver while Mesa still holds
        // allocations (LeakSanitizer reports them); the display goes with the process.
    }
}

}  // namespace fiblet::viewer
