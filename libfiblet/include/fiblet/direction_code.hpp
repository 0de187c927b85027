// fiblet — the 8-bit direction code and the local frames it drives.
//
// A direction is expressed in the local frame of the previous segment
// (x = straight ahead). Directions within the spherical cap x >= 1 - ratio
// are stretched onto the half sphere x >= 0, then projected on the
// half-octahedron |x|+|y|+|z| = 1 and quantized on two diagonal axes with
// 16 levels each (high nibble: y+z, low nibble: y-z).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "fiblet/geometry.hpp"

namespace fiblet {

// The helper vector of the Fiblets format: a frame's second axis is
// normalize(axis x C).
inline constexpr float kFrameHelper[3] = {-0.703023156622f, 0.039959276793f, 0.71004344758f};

// Orthonormal frame, stored as its three columns (c[0] = axis).
struct Frame {
    std::array<Vec3f, 3> c;
};

// The frame built from a unit axis: c0 = axis, c1 = normalize(c0 x C),
// c2 = normalize(c0 x c1). When the axis is within 0.06 degrees of C (the
// cross product vanishes) fiblet uses normalize(C x (1,0,0)) as the helper
// instead, so the frame stays orthonormal (see formats/fft.md).
Frame frame_from_axis(Vec3f unit_axis);
// Whether frame_from_axis takes that fallback helper (|axis x C|^2 < 1e-6 in
// float): the original decoder has none, so it turns such a frame about
// its axis.
bool frame_uses_fallback(Vec3f unit_axis);

// Half sphere (x >= 0) <-> spherical cap (x >= 1 - ratio), unit vectors.
Vec3f map_half_sphere_to_cap(Vec3f v, float ratio);
Vec3f map_cap_to_half_sphere(Vec3f v, float ratio);

// Half-octahedron code: the formula code of a direction (directions with
// x < 0 are projected onto the rim x = 0 first), and the unit direction of a
// code on the half sphere.
std::uint8_t quantize_half_octahedron(Vec3f dir);
Vec3f dequantize_half_octahedron(std::uint8_t code);

// The 256 local frames of a file: entry k is frame_from_axis of code k's
// direction mapped to the cap of `ratio`, computed in double and rounded to
// float (the float formulas lose digits in narrow caps). Built once per file.
class DirectionTable {
public:
    explicit DirectionTable(float ratio);
    float ratio() const { return ratio_; }
    const Frame& frame(std::uint8_t code) const { return frames_[code]; }
    const Vec3f& direction(std::uint8_t code) const { return frames_[code].c[0]; }
    // The code whose cap direction is closest in angle to `local_dir`
    // (any length): the formula code refined over its 3x3 neighbourhood.
    std::uint8_t nearest_code(Vec3f local_dir) const;

private:
    float ratio_;
    std::array<Frame, 256> frames_;
};

// The wide direction codes of the 16-bit layouts (formats/fft16.md): the
// same cap mapping and half-octahedron, quantized with `levels` levels on
// each diagonal axis; the code is level(y+z) * levels + level(y-z).
// Version 16 has 256 levels (the high byte holds y+z), version 17 has 181
// (15-bit codes; an odd count has a straight-ahead code).
inline constexpr unsigned kCodeLevels16 = 256;
inline constexpr unsigned kCodeLevels15 = 181;
std::uint16_t quantize_half_octahedron16(Vec3f dir, unsigned levels = kCodeLevels16);
Vec3f dequantize_half_octahedron16(std::uint16_t code, unsigned levels = kCodeLevels16);

// The levels^2 local frames of a 16-bit file (built once per file), in a
// table of 65536 (2.4 MB).
class DirectionTable16 {
public:
    explicit DirectionTable16(float ratio, unsigned levels = kCodeLevels16);
    float ratio() const { return ratio_; }
    unsigned levels() const { return levels_; }
    std::uint32_t code_count() const { return levels_ * levels_; }
    const Frame& frame(std::uint16_t code) const { return frames_[code]; }
    const Vec3f& direction(std::uint16_t code) const { return frames_[code].c[0]; }
    // As DirectionTable::nearest_code, with wide codes.
    std::uint16_t nearest_code(Vec3f local_dir) const;

private:
    float ratio_;
    unsigned levels_;
    std::vector<Frame> frames_;
};

}  // namespace fiblet
