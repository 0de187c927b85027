#include "fiblet/view.hpp"

#include <cmath>
#include <limits>

#include "core/vec_math.hpp"
#include "index/block_spheres.hpp"

namespace fiblet {
using namespace detail;

namespace {
struct Basis {
    Vec3f right, up, back;  // camera axes; the camera looks along -back
};
Basis camera_basis(const Camera& c) {
    const Vec3f back = normalize(c.position - c.target);
    const Vec3f right = normalize(cross(c.up, back));
    return {right, cross(back, right), back};
}
}  // namespace

Mat4 view_matrix(const Camera& c) {
    const Basis b = camera_basis(c);
    return {b.right.x, b.up.x, b.back.x, 0, b.right.y, b.up.y, b.back.y, 0, b.right.z, b.up.z, b.back.z, 0,
            -dot(b.right, c.position), -dot(b.up, c.position), -dot(b.back, c.position), 1};
}

Mat4 projection_matrix(const Camera& c) {
    const float f = 1.0f / std::tan(c.fov_y_deg * float(M_PI) / 360.0f);
    const float n = c.near_mm, fa = c.far_mm;
    return {f / c.aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (fa + n) / (n - fa), -1, 0, 0, 2 * fa * n / (n - fa), 0};
}

Mat4 view_projection_matrix(const Camera& c) {
    const Mat4 p = projection_matrix(c), v = view_matrix(c);
    Mat4 m{};
    for (int col = 0; col < 4; ++col)
        for (int row = 0; row < 4; ++row) {
            float s = 0;
            for (int k = 0; k < 4; ++k) s += p[k * 4 + row] * v[col * 4 + k];
            m[col * 4 + row] = s;
        }
    return m;
}

Frustum frustum_from_camera(const Camera& c) {
    // Planes built geometrically from the camera basis (exact, and the same
    // on the GPU side, which receives these six planes as uniforms).
    const Basis b = camera_basis(c);
    const Vec3f fwd{-b.back.x, -b.back.y, -b.back.z};
    const float ty = std::tan(c.fov_y_deg * float(M_PI) / 360.0f), tx = ty * c.aspect;
    auto through_eye = [&](Vec3f n) {
        n = normalize(n);
        return Plane{n, -dot(n, c.position)};
    };
    Frustum f;
    f.planes[0] = through_eye(tx * fwd + b.right);  // left
    f.planes[1] = through_eye(tx * fwd - b.right);  // right
    f.planes[2] = through_eye(ty * fwd + b.up);     // bottom
    f.planes[3] = through_eye(ty * fwd - b.up);     // top
    f.planes[4] = Plane{fwd, -dot(fwd, c.position) - c.near_mm};
    f.planes[5] = Plane{-1.0f * fwd, dot(fwd, c.position) + c.far_mm};
    return f;
}

bool sphere_intersects_frustum(const Frustum& f, Vec3f center, float radius) {
    for (const Plane& p : f.planes)
        if (dot(p.n, center) + p.d < -radius) return false;
    return true;
}

bool box_intersects_frustum(const Frustum& f, const Aabb& box, float margin) {
    for (const Plane& p : f.planes) {
        // The box corner farthest along the plane's inward normal.
        const Vec3f c{p.n.x >= 0 ? box.max.x : box.min.x, p.n.y >= 0 ? box.max.y : box.min.y,
                      p.n.z >= 0 ? box.max.z : box.min.z};
        if (dot(p.n, c) + p.d < -margin) return false;
    }
    return true;
}

LevelOfDetail::LevelOfDetail(const Camera& c, const Viewport& v, float lod_pixels)
    : position_(c.position),
      back_(camera_basis(c).back),
      tan_half_fov_(std::tan(c.fov_y_deg * float(M_PI) / 360.0f)),
      half_height_(0.5f * float(v.height)),
      lod_pixels_(lod_pixels) {}

float LevelOfDetail::radius_px(Vec3f center, float radius) const {
    const float depth = -dot(back_, center - position_);  // distance along the view direction
    if (depth <= radius) return std::numeric_limits<float>::infinity();
    return radius / (depth * tan_half_fov_) * half_height_;
}

float projected_radius_px(const Camera& c, const Viewport& v, Vec3f center, float radius) {
    return LevelOfDetail(c, v).radius_px(center, radius);
}

bool block_is_coarse(const Camera& c, const Viewport& v, Vec3f center, float radius, float lod_pixels) {
    return LevelOfDetail(c, v, lod_pixels).coarse(center, radius);
}

namespace {
// block_bounding_sphere's arithmetic, inlined into both of its callers below
// (libfiblet builds with -ffp-contract=off: the same operations give the
// same floats in either).
inline Sphere sphere_of(const FftHeader& h, Vec3f a0, Vec3f a1, std::uint32_t n) {
    if (n < 2) return {a0, 0.0f};
    // In double: the squares of a file's extent overflow a float beyond ~1e19 mm.
    const double dx = double(a1.x) - a0.x, dy = double(a1.y) - a0.y, dz = double(a1.z) - a0.z;
    const auto r = float(std::sqrt(dx * dx + dy * dy + dz * dz) + double(n - 2) * h.step * h.scaling);
    const float padded = r * (1 + 1e-5f) + 1e-5f * h.scaling;
    // A foreign file whose blocks span near the float range: saturate, as
    // the index chunk holds finite radii and float distances that far are inf.
    return {a0, std::min(padded, std::numeric_limits<float>::max())};
}

template <class View>
inline Sphere sphere_of_block(const FftHeader& h, const std::uint8_t* bytes) {
    const View v{bytes};
    const auto a = v.anchors_normalized();
    return sphere_of(h, h.to_world(a[0], a[1], a[2]), h.to_world(a[3], a[4], a[5]), v.point_count());
}
}  // namespace

Sphere block_bounding_sphere(const FftHeader& h, const std::uint8_t* bytes) {
    return h.direction_bits() == 16 ? sphere_of_block<BlockView16>(h, bytes) : sphere_of_block<BlockView>(h, bytes);
}

Sphere block_bounding_sphere(const FftHeader& h, Vec3f a0, Vec3f a1, std::uint32_t n) { return sphere_of(h, a0, a1, n); }

namespace detail {
void block_spheres(const FftHeader& h, const std::uint8_t* const* blocks, std::size_t n, Sphere* out) {
    // Blocks may be scattered (a memory mapping): fetch a few ahead.
    auto all = [&](auto view) {
        using View = decltype(view);
        for (std::size_t i = 0; i < n; ++i) {
            if (i + 8 < n) __builtin_prefetch(blocks[i + 8]);
            out[i] = sphere_of_block<View>(h, blocks[i]);
        }
    };
    if (h.direction_bits() == 16) all(BlockView16{});
    else all(BlockView{});
}
}  // namespace detail

}  // namespace fiblet
