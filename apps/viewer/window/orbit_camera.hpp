// Camera placement: an orbit around a target (azimuth, elevation, distance)
// that the window's mouse moves, the named views of the command line, and
// explicit eye / target / up positions. Coordinates are world mm (RAS+ for
// .tck: x right, y anterior, z superior).
#pragma once

#include <string>
#include <vector>

#include "fiblet/view.hpp"
#include "scene/gpu_scene.hpp"

namespace fiblet::viewer {

struct OrbitCamera {
    Vec3f target{0, 0, 0};
    float distance = 200;       // mm from the target
    float azimuth_deg = 0;      // around +z, from +x towards +y
    float elevation_deg = 0;    // above the xy plane
    float fov_y_deg = 35;
    SceneBounds bounds;         // sets the near and far planes

    Vec3f eye_direction() const;  // unit, from the target to the eye
    Vec3f up() const;             // unit, orthogonal to eye_direction
    Camera camera(float aspect) const;

    void orbit(float d_azimuth_deg, float d_elevation_deg);  // elevation clamped to +-89.9
    void pan(float dx_px, float dy_px, int viewport_height);  // moves the target with the image
    void zoom(float factor);                                  // distance /= factor
};

// The closest orbit from (azimuth, elevation) that shows every point of
// `points` (with a small margin), looking at the centre of `bounds`.
OrbitCamera fit_orbit(const SceneBounds& bounds, const std::vector<Vec3f>& points, float azimuth_deg,
                      float elevation_deg, float fov_y_deg, float aspect);

// Near and far planes for an eye at `eye` that keep all of `bounds` visible.
void set_clip_planes(Camera& camera, const SceneBounds& bounds);

// A camera from a command-line spec:
//   a view name: left, right, front, back, top, bottom, oblique (fitted to the scene)
//   EX,EY,EZ                    eye position, looking at the scene centre
//   EX,EY,EZ,TX,TY,TZ[,UX,UY,UZ] eye, target and up (default up +z)
// `zoom` > 1 moves a named view closer. Throws fiblet::Error{invalid_argument}.
Camera camera_from_spec(const std::string& spec, const GpuScene& scene, float aspect, float fov_y_deg, float zoom);

// `camera` turned by `degrees` around the axis through its target along its
// up vector (right-handed), with near and far planes for `bounds`; 0
// degrees returns it unchanged. Frame i of n of a turntable movie is
// turned_about_up(start, 360 i / n, bounds).
Camera turned_about_up(const Camera& camera, float degrees, const SceneBounds& bounds);

// The named view's (azimuth, elevation), or false for an unknown name.
bool named_view(const std::string& name, float& azimuth_deg, float& elevation_deg);

}  // namespace fiblet::viewer
