// Internal: the handful of float vector operations the codec needs. Kept
// inline and explicit (no expression templates) so that the encoder's
// closed loop and the scalar reference decoder perform the very same
// float operations in the same order.
#pragma once

#include <cmath>

#include "fiblet/direction_code.hpp"
#include "fiblet/geometry.hpp"

namespace fiblet::detail {

inline Vec3f operator+(Vec3f a, Vec3f b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3f operator-(Vec3f a, Vec3f b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3f operator*(float s, Vec3f a) { return {s * a.x, s * a.y, s * a.z}; }
inline float dot(Vec3f a, Vec3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3f cross(Vec3f a, Vec3f b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float norm(Vec3f a) { return std::sqrt(dot(a, a)); }
inline Vec3f normalize(Vec3f a) { return (1.0f / norm(a)) * a; }

// Distances between float points, computed in double: compress's point
// errors and lengths, the end placement and the tuning all measure with
// these, so their figures agree to the last bit.
inline double distance2(Vec3f a, Vec3f b) {
    const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
    return dx * dx + dy * dy + dz * dz;
}
inline double distance(Vec3f a, Vec3f b) { return std::sqrt(distance2(a, b)); }

// Frame applied to a local vector: F * v = v.x c0 + v.y c1 + v.z c2.
inline Vec3f apply(const Frame& f, Vec3f v) {
    return {f.c[0].x * v.x + f.c[1].x * v.y + f.c[2].x * v.z, f.c[0].y * v.x + f.c[1].y * v.y + f.c[2].y * v.z,
            f.c[0].z * v.x + f.c[1].z * v.y + f.c[2].z * v.z};
}
// Transposed frame applied to a world vector: F^T * v (world -> local).
inline Vec3f apply_transposed(const Frame& f, Vec3f v) { return {dot(f.c[0], v), dot(f.c[1], v), dot(f.c[2], v)}; }
// Frame product F * L (columns of L expressed in F).
inline Frame compose(const Frame& f, const Frame& l) { return {{apply(f, l.c[0]), apply(f, l.c[1]), apply(f, l.c[2])}}; }

}  // namespace fiblet::detail
