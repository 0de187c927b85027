// fiblet — the camera, view frustum and level-of-detail rules shared by the
// CPU selective decoder and the GPU viewer (one definition, two users).
#pragma once

#include <array>
#include <cstdint>

#include "fiblet/fft_format.hpp"
#include "fiblet/geometry.hpp"

namespace fiblet {

// A perspective camera in world millimetres (right-handed, OpenGL clip
// conventions: looks along target - position, depth range [-1, 1]).
struct Camera {
    Vec3f position{0, 0, 200};
    Vec3f target{0, 0, 0};
    Vec3f up{0, 1, 0};
    float fov_y_deg = 45;  // vertical field of view
    float aspect = 16.0f / 9.0f;
    float near_mm = 1;
    float far_mm = 2000;
};

struct Viewport {
    int width = 1920, height = 1080;
};

// 4x4 matrices, column-major (as OpenGL's glUniformMatrix4fv expects).
using Mat4 = std::array<float, 16>;
Mat4 view_matrix(const Camera& c);
Mat4 projection_matrix(const Camera& c);
Mat4 view_projection_matrix(const Camera& c);

// Plane n.p + d = 0 with unit n pointing inside the frustum.
struct Plane {
    Vec3f n;
    float d;
};
struct Frustum {
    std::array<Plane, 6> planes;  // left, right, bottom, top, near, far
};
Frustum frustum_from_camera(const Camera& c);

// Conservative: false only when the sphere lies entirely outside one plane.
bool sphere_intersects_frustum(const Frustum& f, Vec3f center, float radius);

// Axis-aligned box in world mm (min <= max on each axis).
struct Aabb {
    Vec3f min, max;
};

// Conservative: false only when the box, grown by `margin` mm in every
// direction, lies entirely outside one plane. With margin = r it is true for
// every sphere of radius <= r centred in the box that meets the frustum.
bool box_intersects_frustum(const Frustum& f, const Aabb& box, float margin = 0);

// Radius in pixels of a sphere's projection (vertical), measured at its
// centre's depth; +infinity when the sphere reaches the camera plane.
float projected_radius_px(const Camera& c, const Viewport& v, Vec3f center, float radius);

// Level of detail: a block whose projected bounding sphere spans fewer than
// `lod_pixels` pixels (diameter) is drawn as one segment from its first point
// to the next block's first point (the paper uses ~4 px).
inline constexpr float kDefaultLodPixels = 4.0f;
bool block_is_coarse(const Camera& c, const Viewport& v, Vec3f center, float radius,
                     float lod_pixels = kDefaultLodPixels);

// The two functions above for many spheres: the camera's terms computed
// once (they are defined through this class, so the results are the same).
class LevelOfDetail {
public:
    LevelOfDetail(const Camera& c, const Viewport& v, float lod_pixels = kDefaultLodPixels);
    float radius_px(Vec3f center, float radius) const;
    bool coarse(Vec3f center, float radius) const { return 2.0f * radius_px(center, radius) < lod_pixels_; }

private:
    Vec3f position_, back_;
    float tan_half_fov_, half_height_, lod_pixels_;
};

// Bounding sphere of a block from its header fields alone (no decoding):
// centre at the first anchor, radius |anchor1 - anchor0| + (n - 2) * step,
// since every later point is one step from the previous one; a one-point
// block has radius 0. In world mm; a relative 1e-5 margin covers float
// rounding of the decoder.
struct Sphere {
    Vec3f center;
    float radius;
};
Sphere block_bounding_sphere(const FftHeader& h, const std::uint8_t* block);
// The same sphere from the block's first two decoded points (world mm) and
// its point count, for code that holds decoded points rather than bytes.
Sphere block_bounding_sphere(const FftHeader& h, Vec3f first, Vec3f second, std::uint32_t points);

}  // namespace fiblet
