// The few vector operations the viewer's camera code needs (fiblet::Vec3f).
#pragma once

#include <cmath>

#include "fiblet/geometry.hpp"

namespace fiblet::viewer {

inline Vec3f add(Vec3f a, Vec3f b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3f sub(Vec3f a, Vec3f b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3f scale(float s, Vec3f a) { return {s * a.x, s * a.y, s * a.z}; }
inline float dot(Vec3f a, Vec3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3f cross(Vec3f a, Vec3f b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline float length(Vec3f a) { return std::sqrt(dot(a, a)); }
inline Vec3f normalized(Vec3f a) {
    const float n = length(a);
    return n > 0 ? scale(1.0f / n, a) : a;
}

}  // namespace fiblet::viewer
