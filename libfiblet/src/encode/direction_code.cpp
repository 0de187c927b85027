#include "fiblet/direction_code.hpp"

#include <algorithm>
#include <cmath>

#include "encode/exact_model.hpp"
#include "core/vec_math.hpp"

namespace fiblet {
using namespace detail;

namespace {
bool needs_fallback(Vec3f c1) { return dot(c1, c1) < 1e-6f; }
}  // namespace

bool frame_uses_fallback(Vec3f axis) {
    return needs_fallback(cross(axis, Vec3f{kFrameHelper[0], kFrameHelper[1], kFrameHelper[2]}));
}

Frame frame_from_axis(Vec3f axis) {
    const Vec3f helper{kFrameHelper[0], kFrameHelper[1], kFrameHelper[2]};
    Vec3f c1 = cross(axis, helper);
    // |axis x C|^2 < 1e-6: the axis is within ~0.06 deg of C; C's own frame
    // would be ill-conditioned, so use the helper C x (1,0,0) (orthogonal to C).
    if (needs_fallback(c1)) c1 = cross(axis, Vec3f{0.0f, helper.z, -helper.y});
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
    // Encoder side only (decoders use the forward map), so computed for
    // accuracy: near the axis 1 - v.x^2 cancels in float, and a 16-bit code
    // is finer than that error. For a unit v, 1 - v.x = (y^2 + z^2) / (1 + v.x).
    const float s2 = v.y * v.y + v.z * v.z;
    const float d = v.x >= 0.0f ? s2 / (1.0f + v.x) : 1.0f - v.x;  // 1 - v.x
    const float e = d / ratio;                                       // 1 - x
    if (!(s2 > 0.0f)) return {1.0f - e, 0.0f, 0.0f};
    const float lateral = std::sqrt(std::max(e * (2.0f - e), 0.0f) / s2);
    return {1.0f - e, v.y * lateral, v.z * lateral};
}

namespace {

// Half-octahedron quantizer with `levels` levels per diagonal axis: the
// code is level(y+z) * levels + level(y-z), i.e. the high nibble/byte holds
// y+z. 8-bit codes use 16 levels, 16-bit codes 256 (version 16) or 181
// (version 17).
unsigned quantize_levels(Vec3f d, int levels) {
    const float half = 0.5f * float(levels - 1);
    const float ax = d.x > 0.0f ? d.x : 0.0f;  // below the rim: project onto x = 0
    const float l1 = ax + std::fabs(d.y) + std::fabs(d.z);
    const float vy = l1 > 0.0f ? d.y / l1 : 0.0f;
    const float vz = l1 > 0.0f ? d.z / l1 : 0.0f;
    auto level = [&](float u) {
        return static_cast<unsigned>(std::clamp(std::floor(0.5f + half * (1.0f + u)), 0.0f, float(levels - 1)));
    };
    return level(vy + vz) * unsigned(levels) + level(vy - vz);
}

Vec3f dequantize_levels(unsigned code, int levels) {
    const float half = 0.5f * float(levels - 1);
    const float q1 = float(code / unsigned(levels)) / half - 1.0f;
    const float q2 = float(code % unsigned(levels)) / half - 1.0f;
    const float y = 0.5f * (q1 + q2), z = 0.5f * (q1 - q2);
    return normalize(Vec3f{1.0f - std::fabs(y) - std::fabs(z), y, z});
}

// The code whose cap direction is closest in angle to `local`: the formula
// code of the direction mapped back to the half sphere, refined over its
// 3x3 neighbourhood (the cap mapping bends the cells a little).
template <class Table>
unsigned nearest_levels(const Table& t, Vec3f local, int levels) {
    const float ratio = t.ratio();
    if (!(dot(local, local) > 0.0f)) return quantize_levels(map_cap_to_half_sphere({1, 0, 0}, ratio), levels);
    const Vec3f unit = normalize(local);
    // Outside the cap the code can only lie on the rim: aim along (0, y, z).
    const Vec3f on_half_sphere =
        unit.x >= 1.0f - ratio ? map_cap_to_half_sphere(unit, ratio) : Vec3f{0.0f, unit.y, unit.z};
    const unsigned guess = quantize_levels(on_half_sphere, levels);
    const int h0 = int(guess) / levels, l0 = int(guess) % levels;
    unsigned best = guess;
    float best_dot = dot(t.direction(guess), local);
    for (int h = std::max(h0 - 1, 0); h <= std::min(h0 + 1, levels - 1); ++h)
        for (int l = std::max(l0 - 1, 0); l <= std::min(l0 + 1, levels - 1); ++l) {
            const auto code = unsigned(h * levels + l);
            const float d = dot(t.direction(code), local);
            if (d > best_dot) best_dot = d, best = code;
        }
    return best;
}

}  // namespace

std::uint8_t quantize_half_octahedron(Vec3f d) { return static_cast<std::uint8_t>(quantize_levels(d, 16)); }
Vec3f dequantize_half_octahedron(std::uint8_t code) { return dequantize_levels(code, 16); }
std::uint16_t quantize_half_octahedron16(Vec3f d, unsigned levels) {
    return static_cast<std::uint16_t>(quantize_levels(d, int(levels)));
}
Vec3f dequantize_half_octahedron16(std::uint16_t code, unsigned levels) { return dequantize_levels(code, int(levels)); }

// A code's frame, computed in double and rounded once: the float formulas
// lose digits where the cap is narrow (1 - x^2 cancels for x near 1: at a
// cap ratio of 0.0027, the straight-ahead codes' frames were 3e-5 off, and
// a straight bundle's blocks drifted 1.3 um from the exact decode). Encoder
// and decoders share this table, so they still agree bit for bit.
static Frame rounded_code_frame(unsigned code, unsigned levels, float ratio) {
    const FrameD f = exact_code_frame(code, levels, double(ratio));
    return {{to_float(f.c[0]), to_float(f.c[1]), to_float(f.c[2])}};
}

DirectionTable::DirectionTable(float ratio) : ratio_(ratio) {
    for (unsigned k = 0; k < 256; ++k) frames_[k] = rounded_code_frame(k, 16, ratio);
}

std::uint8_t DirectionTable::nearest_code(Vec3f local) const {
    return static_cast<std::uint8_t>(nearest_levels(*this, local, 16));
}

DirectionTable16::DirectionTable16(float ratio, unsigned levels) : ratio_(ratio), levels_(levels), frames_(65536) {
    for (unsigned k = 0; k < levels * levels; ++k) frames_[k] = rounded_code_frame(k, levels, ratio);
    // Every u16 has a frame, so no block bytes index past the table: codes
    // past levels^2 (FftFile rejects them) repeat the central code's frame.
    for (unsigned k = levels * levels; k < 65536; ++k) frames_[k] = frames_[levels / 2 * (levels + 1)];
}

std::uint16_t DirectionTable16::nearest_code(Vec3f local) const {
    return static_cast<std::uint16_t>(nearest_levels(*this, local, int(levels_)));
}

}  // namespace fiblet
