// Internal: the encoder's model of an exact (float64) decoder of 8-bit files.
//
// fiblet's decoders run in float32, and the encoder's closed loop reproduces
// them bit for bit. Another conforming reader (numpy in double, a GPU whose
// division rounds differently) starts each block from a slightly different
// first frame. The difference is a rigid motion of the whole block, and it
// is large exactly where the first frame is ill-conditioned: its second axis
// is normalize(F0 x C), so where the first segment runs nearly along the
// helper vector C, the anchors' float rounding (1e-5 rad of axis for a
// 0.1 mm step) turns the block about its axis by that divided by |F0 x C|.
// 16-bit files start both decoders from the same axis (fft16.md), but over
// a 254-point block the float walk's rounding drifts from the exact walk by
// up to ~0.1 um, so the encoder measures there too (only (a) below).
// The encoder uses this model to (a) measure every point's error under the
// exact decode as well, so the header's max error holds for both, and (b)
// in ill-conditioned blocks, aim the codes at the middle of the two
// decoders' targets, so neither decoder pays the whole difference.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "fiblet/direction_code.hpp"
#include "fiblet/geometry.hpp"

namespace fiblet::detail {

struct Vec3d {
    double x = 0, y = 0, z = 0;
};
inline Vec3d operator+(Vec3d a, Vec3d b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3d operator-(Vec3d a, Vec3d b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3d operator*(double s, Vec3d a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(Vec3d a, Vec3d b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3d to_double(Vec3f v) { return {v.x, v.y, v.z}; }
inline Vec3f to_float(Vec3d v) { return {float(v.x), float(v.y), float(v.z)}; }

struct FrameD {
    std::array<Vec3d, 3> c;  // columns; c[0] = axis
};

// frame_from_axis (formats/fft.md §4) in double, with the same fallback helper.
FrameD exact_frame_from_axis(Vec3d unit_axis);
// Whether that takes the fallback helper (|axis x C|^2 < 1e-6 in double).
bool exact_frame_uses_fallback(Vec3d unit_axis);
// The first frame of a block from its anchors (normalized, exact unorm
// values); coinciding anchors give the +x axis, as in every decoder.
FrameD exact_block_frame(Vec3d anchor0, Vec3d anchor1);
// Its axis: the unit first segment, (1, 0, 0) when the anchors coincide.
Vec3d exact_block_axis(Vec3d anchor0, Vec3d anchor1);

// F * v, F^T * v, F * L (inline: the exact walk composes a frame a point).
inline Vec3d apply(const FrameD& f, Vec3d v) { return v.x * f.c[0] + v.y * f.c[1] + v.z * f.c[2]; }
inline Vec3d apply_transposed(const FrameD& f, Vec3d v) { return {dot(f.c[0], v), dot(f.c[1], v), dot(f.c[2], v)}; }
inline FrameD compose(const FrameD& f, const FrameD& l) { return {{apply(f, l.c[0]), apply(f, l.c[1]), apply(f, l.c[2])}}; }

// The direction of a code with `levels` levels per diagonal axis (16 for
// 8-bit codes, 256 for 16-bit ones) in the cap of `ratio`, from the
// format's formulas in double, and its local frame.
Vec3d exact_code_direction(unsigned code, unsigned levels, double ratio);
FrameD exact_code_frame(unsigned code, unsigned levels, double ratio);

// The 256 local frames of a ratio, computed from the format's formulas in
// double (not from the float table).
class ExactDirectionTable {
public:
    explicit ExactDirectionTable(float ratio);
    const FrameD& frame(std::uint8_t code) const { return frames_[code]; }

private:
    std::array<FrameD, 256> frames_;
};

// The levels^2 local frames of 16-bit codes (fft16.md), in double.
class ExactDirectionTable16 {
public:
    ExactDirectionTable16(float ratio, unsigned levels);
    const FrameD& frame(std::uint16_t code) const { return frames_[code < frames_.size() ? code : frames_.size() / 2]; }

private:
    std::vector<FrameD> frames_;
};

// The first frame of a 16-bit block from its anchors' unorm24 integers: the
// axis of their exact difference (fft16.md, version 17; version 16's float
// anchors differ from it only by the float decoder's rounding).
FrameD exact_block_frame24(const std::array<std::uint32_t, 3>& q0, const std::array<std::uint32_t, 3>& q1);

// Decodes the direction codes of one block exactly from its second anchor
// and first frame (normalized coordinates): writes `count` points.
void exact_walk(const ExactDirectionTable& table, FrameD f, Vec3d p, double step, const std::uint8_t* codes,
                std::size_t count, Vec3d* out);
void exact_walk(const ExactDirectionTable16& table, FrameD f, Vec3d p, double step, const std::uint16_t* codes,
                std::size_t count, Vec3d* out);

// The unorm16 value of an anchor coordinate, exactly.
inline double exact_unorm16(std::uint32_t q) { return double(q) / 65535.0; }

}  // namespace fiblet::detail
