#include "fiblet_viewer/viewer_window.hpp"

#include <fmt/core.h>
#include <epoxy/gl.h>
// GLFW after epoxy: epoxy provides the GL declarations.
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <utility>

#include "overlays/overlay_sources.hpp"
#include "window/control_panel.hpp"
#include "window/fiber_picking.hpp"
#include "window/fiber_selection.hpp"
#include "fiblet/error.hpp"
#include "scene/gpu_programs.hpp"
#include "scene/gpu_scene.hpp"
#include "gl/gl_info.hpp"
#include "window/orbit_camera.hpp"
#include "gl/png_file.hpp"
#include "render/render_target.hpp"
#include "render/renderer.hpp"
#include "techniques/technique_registry.hpp"
#include "window/streamed_view.hpp"
#include "render/supersampling.hpp"
#include "scene/scene_file.hpp"
#include "render/vec_ops.hpp"

namespace fiblet::viewer {

const char* window_controls_help() {
    return "  left drag: orbit    right/middle drag or shift+left drag: pan    wheel: zoom\n"
           "  click: highlight the fiber under the cursor and print it (ID, points, length); on the background: "
           "clear\n"
           "  shift+click: add the fiber to the highlighted ones (or take it out)    W: save them as a fiber list\n"
           "  R: reset view    S: screenshot (PNG)    C: culling on/off    L: level of detail on/off\n"
           "  D: colour by direction / fixed    I: lighting on/off    +/-: line width    T: lines / tubes / capsules\n"
           "  E: engine raster / voxel-rt    P: control panel on/off    ?: keys in the window    H: help    "
           "Q, Esc: quit\n";
}

namespace {

std::string glfw_error;  // the last GLFW error message (GLFW reports through a callback)

struct GlfwSession {
    GlfwSession() {
        glfwSetErrorCallback([](int, const char* message) { glfw_error = message ? message : "unknown error"; });
        if (!glfwInit())
            throw Error(Errc::unsupported,
                        "cannot open a window: " + glfw_error +
                            (std::getenv("DISPLAY") || std::getenv("WAYLAND_DISPLAY")
                                 ? std::string()
                                 : std::string(" (no display: DISPLAY and WAYLAND_DISPLAY are unset)")) +
                            "; `fiblet render` draws to a PNG without a display");
    }
    ~GlfwSession() { glfwTerminate(); }
    GlfwSession(const GlfwSession&) = delete;
    GlfwSession& operator=(const GlfwSession&) = delete;
};

// Dear ImGui on the window: its GLFW callbacks chain to the window's, which
// are installed first.
struct ImGuiSession {
    explicit ImGuiSession(GLFWwindow* w) {
        IMGUI_CHECKVERSION();
        ImGui::CreateContext();
        ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the working directory
        ImGui_ImplGlfw_InitForOpenGL(w, true);
        ImGui_ImplOpenGL3_Init("#version 450 core");
    }
    ~ImGuiSession() {
        ImGui_ImplOpenGL3_Shutdown();
        ImGui_ImplGlfw_Shutdown();
        ImGui::DestroyContext();
    }
    ImGuiSession(const ImGuiSession&) = delete;
    ImGuiSession& operator=(const ImGuiSession&) = delete;
};

struct WindowDeleter {
    void operator()(GLFWwindow* w) const { glfwDestroyWindow(w); }
};

// The state the GLFW callbacks change.
struct Interaction {
    OrbitCamera orbit, home;
    RenderOptions render;
    bool dirty = true, screenshot = false, quit = false;
    bool dragging = false, panning = false, moved = false;
    double press_x = 0, press_y = 0, last_x = 0, last_y = 0;
    std::optional<std::pair<double, double>> pick;  // window coordinates of a click
    bool pick_adds = false;                          // a shift-click: add to the selection
    bool save_selection = false;
    ControlPanel panel;
};

// Whether the panel takes this event (the pointer or the keyboard is its).
bool panel_takes_mouse() { return ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse; }
bool panel_takes_keys() { return ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureKeyboard; }

Interaction& state_of(GLFWwindow* w) { return *static_cast<Interaction*>(glfwGetWindowUserPointer(w)); }

void on_key(GLFWwindow* w, int key, int, int action, int mods) {
    if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
    if (panel_takes_keys()) return;
    Interaction& s = state_of(w);
    switch (key) {
        case GLFW_KEY_P: s.panel.visible = !s.panel.visible; return;
        case GLFW_KEY_SLASH:
            if (mods & GLFW_MOD_SHIFT) s.panel.show_keys = !s.panel.show_keys;
            return;
        case GLFW_KEY_ESCAPE:
        case GLFW_KEY_Q: s.quit = true; break;
        case GLFW_KEY_R: s.orbit = s.home; break;
        case GLFW_KEY_S: s.screenshot = true; break;
        case GLFW_KEY_C: s.render.frustum_culling = !s.render.frustum_culling; break;
        case GLFW_KEY_L: s.render.level_of_detail = !s.render.level_of_detail; break;
        case GLFW_KEY_D: s.render.color_by_direction = !s.render.color_by_direction; break;
        case GLFW_KEY_I: s.render.lighting = !s.render.lighting; break;
        case GLFW_KEY_EQUAL:
        case GLFW_KEY_KP_ADD: s.render.line_width = std::min(s.render.line_width + 1, 16.0f); break;
        case GLFW_KEY_MINUS:
        case GLFW_KEY_KP_SUBTRACT: s.render.line_width = std::max(s.render.line_width - 1, 1.0f); break;
        case GLFW_KEY_T:
            s.render.style = next_style(s.render.style);
            break;
        case GLFW_KEY_E:
            s.render.engine = next_engine(s.render.engine);
            break;
        case GLFW_KEY_W: s.save_selection = true; break;
        case GLFW_KEY_H: fmt::print("{}", window_controls_help()); break;
        default: return;
    }
    s.dirty = true;
}

void on_button(GLFWwindow* w, int button, int action, int mods) {
    Interaction& s = state_of(w);
    if (action == GLFW_PRESS && panel_takes_mouse()) return;
    double x = 0, y = 0;
    glfwGetCursorPos(w, &x, &y);
    if (action == GLFW_PRESS) {
        s.dragging = true, s.moved = false;
        s.panning = button != GLFW_MOUSE_BUTTON_LEFT || (mods & GLFW_MOD_SHIFT);
        s.pick_adds = button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_SHIFT);
        s.press_x = s.last_x = x, s.press_y = s.last_y = y;
    } else if (action == GLFW_RELEASE) {
        if (s.dragging && !s.moved && button == GLFW_MOUSE_BUTTON_LEFT) s.pick = std::make_pair(x, y), s.dirty = true;
        s.dragging = false;
    }
}

void on_cursor(GLFWwindow* w, double x, double y) {
    Interaction& s = state_of(w);
    if (!s.dragging) return;
    if (std::abs(x - s.press_x) + std::abs(y - s.press_y) > 3) s.moved = true;
    const double dx = x - s.last_x, dy = y - s.last_y;
    s.last_x = x, s.last_y = y;
    if (!s.moved) return;
    int height = 1;
    glfwGetWindowSize(w, nullptr, &height);
    if (s.panning)
        s.orbit.pan(float(dx), float(dy), height);
    else
        s.orbit.orbit(float(-dx) * 0.3f, float(dy) * 0.3f);
    s.dirty = true;
}

void on_scroll(GLFWwindow* w, double, double dy) {
    if (panel_takes_mouse()) return;
    Interaction& s = state_of(w);
    s.orbit.zoom(std::pow(1.15f, float(dy)));
    s.dirty = true;
}

// The orbit for a --camera spec: named views are fitted; explicit eyes keep
// their eye and target (the up vector follows the orbit).
OrbitCamera initial_orbit(const WindowOptions& o, const GpuScene& scene, float aspect) {
    const SceneBounds& bounds = scene.bounds();
    float az = 0, el = 0;
    if (named_view(o.camera, az, el)) {
        OrbitCamera orbit = fit_orbit(bounds, scene.sample_points(), az, el, o.fov_y_deg, aspect);
        orbit.distance /= o.zoom;
        return orbit;
    }
    const Camera c = camera_from_spec(o.camera, scene, aspect, o.fov_y_deg, o.zoom);
    OrbitCamera orbit = fit_orbit(bounds, scene.sample_points(), 0, 0, o.fov_y_deg, aspect);
    const Vec3f d = sub(c.position, c.target);
    orbit.target = c.target;
    orbit.distance = length(d);
    orbit.azimuth_deg = std::atan2(d.y, d.x) * 180.0f / float(M_PI);
    orbit.elevation_deg = std::clamp(std::asin(d.z / orbit.distance) * 180.0f / float(M_PI), -89.9f, 89.9f);
    return orbit;
}

std::string next_screenshot_name(const std::string& prefix) {
    for (int i = 1;; ++i) {
        const std::string name = fmt::format("{}-{:03}.png", prefix, i);
        if (!std::filesystem::exists(name)) return name;
    }
}

void take_screenshot(const WindowOptions& options, Renderer& renderer, const GpuScene& scene, const Camera& camera,
                     const RenderOptions& render, const RenderTarget& target) {
    const std::string name = next_screenshot_name(options.screenshot_prefix);
    if (options.screenshot_supersample > 1)
        write_png(name,
                  render_supersampled(renderer, scene, camera, render, target.width(), target.height(),
                                      options.screenshot_supersample)
                      .image,
                  false);
    else
        write_png(name, {target.width(), target.height(), target.read_rgba()}, false);
    fmt::print("screenshot: {}\n", name);
    std::fflush(stdout);
}

// The click's fiber into the highlighted ones and the panel; true when the
// target now holds the opaque frame picked from (a transparent frame).
bool pick(Interaction& s, GLFWwindow* w, Renderer& renderer, const GpuScene& scene, const Camera& camera,
          RenderTarget& target, PanelFrame& frame) {
    int win_width = 1, win_height = 1;
    glfwGetWindowSize(w, &win_width, &win_height);
    const int px = int(s.pick->first * target.width() / std::max(win_width, 1));
    const int py = int(s.pick->second * target.height() / std::max(win_height, 1));
    s.pick.reset();
    const bool stale = s.render.transparent();
    const auto f = pick_fiber_in_frame(renderer, scene, camera, s.render, target, px, py);
    if (f)
        fmt::print("fiber ID {} (index {}): {} points, {:.2f} mm\n", f->id, f->index, f->points, f->length_mm);
    else
        fmt::print("no fiber at ({}, {})\n", px, py);
    frame.picked = f;
    if (!update_selection(s.render.highlighted_fibers, f ? std::optional<std::uint64_t>(f->index) : std::nullopt,
                          s.pick_adds))
        fmt::print("at most {} fibers are highlighted\n", kMaxHighlightedFibers);
    s.dirty = true;
    std::fflush(stdout);
    return stale;
}

// `overlays` as the panel left them; `drawn`, those the overlays were made
// from, which a refused change (e.g. a slice outside the image) goes back to.
void apply_panel_requests(const PanelRequests& asked, Interaction& s, OverlaySources& overlays,
                          OverlaySources& drawn, Renderer& renderer, PanelFrame& frame) {
    if (asked.overlays) {
        RenderOptions changed = s.render;
        changed.slab_half_width_mm = 0;  // make_overlays sets it again for a slab
        try {
            renderer.set_overlays(make_overlays(overlays, changed));
            s.render.slab_plane = changed.slab_plane, s.render.slab_half_width_mm = changed.slab_half_width_mm;
            drawn = overlays;
            frame.message.clear();
        } catch (const Error& e) {
            frame.message = e.what();
            overlays = drawn;
        }
    }
    if (asked.clear_selection) s.render.highlighted_fibers.clear(), frame.picked.reset();
    if (asked.save_selection) s.save_selection = true;
    if (asked.render || asked.save_selection) s.dirty = true;
}

// One line per control: label, then its rectangle x0 y0 x1 y1 (window pixels).
void write_panel_layout(const char* path, const PanelLayout& layout) {
    std::FILE* f = std::fopen(path, "w");
    if (!f) return;
    for (const auto& [label, rect] : layout)
        fmt::print(f, "{}\t{:.0f} {:.0f} {:.0f} {:.0f}\n", label, rect.first[0], rect.first[1], rect.second[0],
                   rect.second[1]);
    std::fclose(f);
}

// What the panel offers: the colour sources the scene has, and every
// per-streamline value a picked fiber shows.
PanelScene panel_scene(const FftFile& file, const GpuScene& scene) {
    PanelScene p;
    p.fiber_colors = scene.has_fiber_colors();
    p.point_values = scene.has_point_values();
    p.point_value_range = scene.point_value_range();
    p.fibers = scene.file_fiber_count();
    for (const StreamlineField& f : file.streamline_fields()) {
        if (f.scope() != FieldScope::streamline || f.components != 1 || f.rows() != scene.file_fiber_count()) continue;
        std::vector<float> values(f.rows());
        for (std::uint64_t r = 0; r < f.rows(); ++r) values[r] = narrow_to_float(f.at(r, 0));
        p.fiber_values.emplace_back(f.name, std::move(values));
    }
    return p;
}

void save_highlighted(const WindowOptions& options, const std::vector<std::uint32_t>& fibers) {
    try {
        save_selection(options.selection_path, fibers);
        fmt::print("{} highlighted fibers saved to {} (fiblet extract --fibers $(cat {}))\n", fibers.size(),
                   options.selection_path, options.selection_path);
    } catch (const Error& e) {
        fmt::print(stderr, "fiblet: error: {}\n", e.what());
    }
    std::fflush(stdout);
}

}  // namespace

void run_viewer_window(const std::string& path, const WindowOptions& options) {
    const auto opened = std::chrono::steady_clock::now();
    const GlfwSession glfw;
    const std::string title = std::filesystem::path(path).filename().string();
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_FALSE);  // wide lines stay available
    std::unique_ptr<GLFWwindow, WindowDeleter> window(
        glfwCreateWindow(options.width, options.height, title.c_str(), nullptr, nullptr));
    if (!window) throw Error(Errc::unsupported, "cannot open an OpenGL 4.5 window: " + glfw_error);
    GLFWwindow* w = window.get();
    glfwMakeContextCurrent(w);
    glfwSwapInterval(1);
    require_gl45();

    const GpuPrograms programs;
    const FftFile file = open_scene_file(path);
    const FiberStreaming streaming(file, options.gpu_budget_bytes, !options.fiber_colors.point_values_path.empty());
    GpuScene scene =
        first_scene(file, programs, streaming, options.fiber_colors, options.fiber_radii_path, options.fiber_opacity_source);
    Renderer renderer(programs);
    int fb_width = 0, fb_height = 0;
    glfwGetFramebufferSize(w, &fb_width, &fb_height);
    RenderTarget target(std::max(fb_width, 1), std::max(fb_height, 1));

    Interaction s;
    s.render = options.render;
    s.render.time_stages = true;
    OverlaySources overlays = options.overlays, drawn_overlays = overlays;
    renderer.set_overlays(make_overlays(overlays, s.render));
    s.home = s.orbit = initial_orbit(options, scene, float(target.width()) / float(target.height()));
    glfwSetWindowUserPointer(w, &s);
    glfwSetKeyCallback(w, on_key);
    glfwSetMouseButtonCallback(w, on_button);
    glfwSetCursorPosCallback(w, on_cursor);
    glfwSetScrollCallback(w, on_scroll);
    glfwSetFramebufferSizeCallback(w, [](GLFWwindow* win, int, int) { state_of(win).dirty = true; });
    const ImGuiSession imgui(w);
    const PanelScene panel_info = panel_scene(file, scene);
    PanelFrame frame;
    // The panel's controls, written for the window test (scripts/view_window_test.sh).
    const char* layout_file = std::getenv("FIBLET_VIEW_PANEL_LAYOUT");
    PanelLayout layout;
    fmt::print("{}: {} fibers, {} blocks on {}\n{}", title, file.header().fibers, file.header().blocks,
               current_gl_description(), window_controls_help());
    if (streaming.streams())
        fmt::print("beyond --gpu-memory {:.3g} MiB: an overview of {} fibers first, then the fibers each view sees\n",
                   streaming.budget_bytes() / 1048576.0, scene.fiber_count());
    std::fflush(stdout);
    StreamedView streamed(scene, file, programs, streaming, opened);
    bool first_frame = true;

    while (!glfwWindowShouldClose(w) && !s.quit) {
        // Sleep until something happens; draw the scene again only when the
        // view changed, the panel at every event.
        if (!s.dirty) glfwWaitEventsTimeout(streamed.load_pending() ? 0.1 : 0.5);
        glfwPollEvents();
        glfwGetFramebufferSize(w, &fb_width, &fb_height);
        if (fb_width < 1 || fb_height < 1) continue;  // minimized
        const Camera camera = s.orbit.camera(float(fb_width) / float(fb_height));
        bool loaded = false;  // a streamed file's fibers for this view, after the first frame
        const GpuScene& drawn =
            first_frame ? scene : streamed.scene_for(camera, renderer.reach_mm(scene, s.render), loaded);
        s.dirty = s.dirty || loaded;
        bool target_stale = false;  // a transparent frame's pick drew over it
        if (s.dirty) {
            s.dirty = false;
            target.resize(fb_width, fb_height);
            const auto t0 = std::chrono::steady_clock::now();
            try {
                frame.stats = renderer.render(drawn, camera, s.render, target);
            } catch (const Error& e) {
                // E on a scene the voxel ray tracer refuses (its buffers): say
                // why and keep drawing with the rasterizer.
                if (!ray_traced(s.render) || e.code() != Errc::unsupported) throw;
                fmt::print(stderr, "{}; back to --engine raster\n", e.what());
                frame.message = std::string(e.what()) + "; back to raster";
                s.render.engine = RenderEngine::raster;
                s.dirty = true;
                continue;
            }
            frame.frame_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            frame.gpu_bytes = streamed.gpu_bytes() + renderer.transparency_bytes();
            frame.fibers_held = drawn.fiber_count(), frame.file_fibers = drawn.file_fiber_count();
            if (std::exchange(first_frame, false) || loaded)
                fmt::print("{} frame drawn {:.2f} s after start ({} of {} fibers, {:.0f} ms)\n",
                           loaded ? "the view's fibers'" : "first", seconds_since(opened), drawn.fiber_count(),
                           drawn.file_fiber_count(), frame.frame_ms),
                    std::fflush(stdout);
            glfwSetWindowTitle(w, fmt::format("{} | {:.1f} ms | {} blocks ({} coarse), {} segments | {}", title,
                                              frame.frame_ms, frame.stats.drawn_blocks(), frame.stats.coarse_blocks,
                                              frame.stats.drawn_segments(), technique_label(s.render))
                                      .c_str());
            // Screenshots first (the scene alone, never the panel): picking
            // a transparent frame draws over the target.
            if (s.screenshot) {
                s.screenshot = false;
                take_screenshot(options, renderer, drawn, camera, s.render, target);
            }
            if (s.pick) target_stale = pick(s, w, renderer, drawn, camera, target, frame);
        }
        if (s.save_selection) {
            s.save_selection = false;
            save_highlighted(options, s.render.highlighted_fibers);
        }
        if (target_stale) continue;  // drawn again at once

        glNamedFramebufferReadBuffer(target.framebuffer(), GL_COLOR_ATTACHMENT0);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glBlitNamedFramebuffer(target.framebuffer(), 0, 0, 0, target.width(), target.height(), 0, 0, fb_width,
                               fb_height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        frame.highlighted = s.render.highlighted_fibers.size();
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        const PanelRequests asked = s.panel.draw(s.render, overlays, panel_info, frame, layout_file ? &layout : nullptr);
        if (layout_file) write_panel_layout(layout_file, layout);
        ImGui::Render();
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        glfwSwapBuffers(w);
        apply_panel_requests(asked, s, overlays, drawn_overlays, renderer, frame);
    }
}

}  // namespace fiblet::viewer
