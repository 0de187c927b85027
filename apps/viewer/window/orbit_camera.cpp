#include "window/orbit_camera.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "fiblet/error.hpp"
#include "render/vec_ops.hpp"

namespace fiblet::viewer {

namespace {
constexpr float kDegrees = float(M_PI) / 180.0f;
}

Vec3f OrbitCamera::eye_direction() const {
    const float az = azimuth_deg * kDegrees, el = elevation_deg * kDegrees;
    return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}

Vec3f OrbitCamera::up() const {
    // The derivative of the eye direction along elevation: defined at the poles too.
    const float az = azimuth_deg * kDegrees, el = elevation_deg * kDegrees;
    return {-std::sin(el) * std::cos(az), -std::sin(el) * std::sin(az), std::cos(el)};
}

Camera OrbitCamera::camera(float aspect) const {
    Camera c;
    c.position = add(target, scale(distance, eye_direction()));
    c.target = target;
    c.up = up();
    c.fov_y_deg = fov_y_deg;
    c.aspect = aspect;
    set_clip_planes(c, bounds);
    return c;
}

void OrbitCamera::orbit(float d_az, float d_el) {
    azimuth_deg = std::fmod(azimuth_deg + d_az, 360.0f);
    elevation_deg = std::clamp(elevation_deg + d_el, -89.9f, 89.9f);
}

void OrbitCamera::pan(float dx_px, float dy_px, int viewport_height) {
    // Pixels to mm at the target's depth.
    const float mm_per_px = 2.0f * distance * std::tan(fov_y_deg * kDegrees / 2) / float(std::max(viewport_height, 1));
    const Vec3f back = eye_direction(), up_axis = up();
    const Vec3f right = cross(up_axis, back);
    target = add(target, add(scale(-dx_px * mm_per_px, right), scale(dy_px * mm_per_px, up_axis)));
}

void OrbitCamera::zoom(float factor) {
    if (factor > 0) distance = std::clamp(distance / factor, bounds.radius() * 1e-3f, bounds.radius() * 1e3f);
}

OrbitCamera fit_orbit(const SceneBounds& bounds, const std::vector<Vec3f>& points, float azimuth_deg,
                      float elevation_deg, float fov_y_deg, float aspect) {
    OrbitCamera o;
    o.target = bounds.center();
    o.azimuth_deg = azimuth_deg, o.elevation_deg = elevation_deg;
    o.fov_y_deg = fov_y_deg;
    o.bounds = bounds;
    // The closest distance at which every point is in view (a point at depth
    // z towards the eye needs |x| <= tan(half fov) (d - z)).
    const Vec3f back = o.eye_direction(), up = o.up(), right = cross(up, back);
    const float ty = std::tan(fov_y_deg * kDegrees / 2), tx = ty * aspect;
    float d = 0;
    for (const Vec3f& p : points) {
        const Vec3f v = sub(p, o.target);
        const float z = dot(v, back);
        d = std::max({d, z + std::fabs(dot(v, right)) / tx, z + std::fabs(dot(v, up)) / ty});
    }
    o.distance = std::max(1.06f * d, bounds.radius() * 1e-2f);
    return o;
}

void set_clip_planes(Camera& c, const SceneBounds& bounds) {
    const float r = std::max(bounds.radius(), 1e-3f);
    const float d = length(sub(c.position, bounds.center()));
    c.near_mm = std::max(d - 1.01f * r, r * 1e-3f);
    c.far_mm = d + 1.01f * r;
}

bool named_view(const std::string& name, float& az, float& el) {
    struct View {
        const char* name;
        float az, el;
    };
    static constexpr View kViews[] = {{"right", 0, 0},  {"front", 90, 0},  {"left", 180, 0},    {"back", -90, 0},
                                      {"top", -90, 90}, {"bottom", 90, -90}, {"oblique", 145, 25}};
    for (const View& v : kViews)
        if (name == v.name) {
            az = v.az, el = v.el;
            return true;
        }
    return false;
}

Camera camera_from_spec(const std::string& spec, const GpuScene& scene, float aspect, float fov_y_deg, float zoom) {
    const SceneBounds& bounds = scene.bounds();
    if (!(fov_y_deg > 0 && fov_y_deg < 180)) throw Error(Errc::invalid_argument, "--fov must be in (0, 180) degrees");
    if (!(zoom > 0)) throw Error(Errc::invalid_argument, "--zoom must be positive");
    float az = 0, el = 0;
    if (named_view(spec, az, el)) {
        OrbitCamera o = fit_orbit(bounds, scene.sample_points(), az, el, fov_y_deg, aspect);
        o.distance /= zoom;
        return o.camera(aspect);
    }
    std::vector<float> v;
    std::stringstream ss(spec);
    for (std::string item; std::getline(ss, item, ',');) {
        char* end = nullptr;
        const float x = std::strtof(item.c_str(), &end);
        if (item.empty() || *end != '\0' || !std::isfinite(x))
            throw Error(Errc::invalid_argument, "--camera: '" + spec +
                                                    "' is neither a view name (left, right, front, back, top, "
                                                    "bottom, oblique) nor 3, 6 or 9 numbers");
        v.push_back(x);
    }
    if (v.size() != 3 && v.size() != 6 && v.size() != 9)
        throw Error(Errc::invalid_argument, "--camera takes 3 (eye), 6 (eye, target) or 9 (eye, target, up) numbers");
    Camera c;
    c.position = {v[0], v[1], v[2]};
    c.target = v.size() >= 6 ? Vec3f{v[3], v[4], v[5]} : bounds.center();
    c.up = v.size() == 9 ? Vec3f{v[6], v[7], v[8]} : Vec3f{0, 0, 1};
    const Vec3f forward = sub(c.target, c.position);
    if (!(length(forward) > 0)) throw Error(Errc::invalid_argument, "--camera: the eye is on the target");
    if (!(length(cross(forward, c.up)) > 1e-6f * length(forward) * length(c.up))) {
        if (v.size() == 9) throw Error(Errc::invalid_argument, "--camera: the up vector is along the view direction");
        c.up = {0, 1, 0};
    }
    c.fov_y_deg = fov_y_deg;
    c.aspect = aspect;
    set_clip_planes(c, bounds);
    return c;
}

Camera turned_about_up(const Camera& camera, float degrees, const SceneBounds& bounds) {
    if (degrees == 0) return camera;
    // Rodrigues' rotation of the eye around the target.
    const Vec3f k = normalized(camera.up), v = sub(camera.position, camera.target);
    const float a = degrees * float(M_PI) / 180.0f, c = std::cos(a), s = std::sin(a);
    const Vec3f turned = add(add(scale(c, v), scale(s, cross(k, v))), scale(dot(k, v) * (1 - c), k));
    Camera out = camera;
    out.position = add(camera.target, turned);
    set_clip_planes(out, bounds);
    return out;
}

}  // namespace fiblet::viewer
