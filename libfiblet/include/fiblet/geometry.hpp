// fiblet — the small value types shared by the public API.
#pragma once

#include <cstdint>

namespace fiblet {

// A point or a vector in world millimetres (float32, as in .tck and TRX).
struct Vec3f {
    float x = 0, y = 0, z = 0;
};

inline bool operator==(const Vec3f& a, const Vec3f& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

}  // namespace fiblet
