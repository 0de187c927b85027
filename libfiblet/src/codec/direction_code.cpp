#include "fiblet/direction_code.hpp"

#include <algorithm>
#include <cmath>

#include "core/vec_math.hpp"

namespace fiblet {
using namespace detail;

Frame frame_from_axis(Vec3f axis) {
    const Vec3f helper{kFrameHelper[0], kFrameHelper[1], kFrameHelper[2]};
    Vec3f c1 = cross(axis, helper);
    // |axis x C|^2 < 1e-6: the axis is within ~0.06 deg of C; C's own frame
    // would be ill-conditioned, so use the helper C x (1,0,0) (orthogonal to C).
    if (dot(c1, c1) < 1e-6f) c1 = cross(axis, Vec3f{0.0f, helper.z, -helper.y});
    c1 = normalize(c1);
    const Vec3f c2 = normalize(cross(axis, c1));
    return {{axis, c1, c2}};
}

Vec3f map_half_sphere_to_cap(Vec3f v, float ratio) {
    const float x = 1.0f - ratio + ratio * v.x;
    // Scale y, z so the result stays unit length; v.x < 1 for every code.
    const float lateral = std::sqrt(std::max(1.0f - x * x, 0.0f) / std::max(1.0f - v.x * v.x, 1e-12f));
    return {x, v.y * lateral, v.z * lateral};
}

Vec3f map_cap_to_half_sphere(Vec3f v, float ratio) {
    const float x = (v.x + ratio - 1.0f) / ratio;
    const float lateral = std::sqrt(std::max(1.0f - x * x, 0.0f) / std::max(1.0f - v.x * v.x, 1e-12f));
    return {x, v.y * lateral, v.z * lateral};
}

std::uint8_t quantize_half_octahedron(Vec3f d) {
    const float ax = d.x > 0.0f ? d.x : 0.0f;  // below the rim: project onto x = 0
    const float l1 = ax + std::fabs(d.y) + std::fabs(d.z);
    const float vy = l1 > 0.0f ? d.y / l1 : 0.0f;
    const float vz = l1 > 0.0f ? d.z / l1 : 0.0f;
    auto level = [](float u) {
        return static_cast<std::uint8_t>(std::clamp(std::floor(0.5f + 7.5f * (1.0f + u)), 0.0f, 15.0f));
    };
    return static_cast<std::uint8_t>(level(vy + vz) << 4 | level(vy - vz));
}

Vec3f dequantize_half_octahedron(std::uint8_t code) {
    const float q1 = float(code >> 4) / 7.5f - 1.0f;
    const float q2 = float(code & 15) / 7.5f - 1.0f;
    const float y = 0.5f * (q1 + q2), z = 0.5f * (q1 - q2);
    return normalize(Vec3f{1.0f - std::fabs(y) - std::fabs(z), y, z});
}

DirectionTable::DirectionTable(float ratio) : ratio_(ratio) {
    for (int k = 0; k < 256; ++k) {
        const Vec3f d = normalize(map_half_sphere_to_cap(dequantize_half_octahedron(std::uint8_t(k)), ratio));
        frames_[k] = frame_from_axis(d);
    }
}

std::uint8_t DirectionTable::nearest_code(Vec3f local) const {
    if (!(dot(local, local) > 0.0f)) return quantize_half_octahedron(map_cap_to_half_sphere({1, 0, 0}, ratio_));
    const Vec3f unit = normalize(local);
    // Outside the cap the code can only lie on the rim: aim along (0, y, z).
    const Vec3f on_half_sphere =
        unit.x >= 1.0f - ratio_ ? map_cap_to_half_sphere(unit, ratio_) : Vec3f{0.0f, unit.y, unit.z};
    const std::uint8_t guess = quantize_half_octahedron(on_half_sphere);
    const int h0 = guess >> 4, l0 = guess & 15;
    std::uint8_t best = guess;
    float best_dot = dot(direction(guess), local);
    for (int h = std::max(h0 - 1, 0); h <= std::min(h0 + 1, 15); ++h)
        for (int l = std::max(l0 - 1, 0); l <= std::min(l0 + 1, 15); ++l) {
            const auto code = static_cast<std::uint8_t>(h << 4 | l);
            const float d = dot(direction(code), local);
            if (d > best_dot) best_dot = d, best = code;
        }
    return best;
}

}  // namespace fiblet
