#include "encode/exact_model.hpp"

#include <algorithm>

namespace fiblet::detail {

namespace {

Vec3d cross(Vec3d a, Vec3d b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
Vec3d unit(Vec3d a) { return (1.0 / std::sqrt(dot(a, a))) * a; }

const Vec3d kHelper{kFrameHelper[0], kFrameHelper[1], kFrameHelper[2]};
bool needs_fallback(Vec3d c1) { return dot(c1, c1) < 1e-6; }

}  // namespace

bool exact_frame_uses_fallback(Vec3d axis) { return needs_fallback(cross(axis, kHelper)); }

FrameD exact_frame_from_axis(Vec3d axis) {
    Vec3d c1 = cross(axis, kHelper);
    if (needs_fallback(c1)) c1 = cross(axis, Vec3d{0.0, kHelper.z, -kHelper.y});
    c1 = unit(c1);
    return {{axis, c1, unit(cross(axis, c1))}};
}

Vec3d exact_block_axis(Vec3d a0, Vec3d a1) {
    const Vec3d d = a1 - a0;
    return dot(d, d) > 0 ? unit(d) : Vec3d{1, 0, 0};
}

FrameD exact_block_frame(Vec3d a0, Vec3d a1) { return exact_frame_from_axis(exact_block_axis(a0, a1)); }

// formats/fft.md §4, decoding side; fft16.md for 256 levels.
Vec3d exact_code_direction(unsigned code, unsigned levels, double ratio) {
    const double half = 0.5 * double(levels - 1);
    const double q1 = double(code / levels) / half - 1, q2 = double(code % levels) / half - 1;
    const double y = 0.5 * (q1 + q2), z = 0.5 * (q1 - q2);
    const Vec3d d = unit({1 - std::fabs(y) - std::fabs(z), y, z});
    const double x = 1 - ratio + ratio * d.x;
    const double lateral = std::sqrt(std::max(1 - x * x, 0.0) / std::max(1 - d.x * d.x, 1e-300));
    return unit({x, d.y * lateral, d.z * lateral});
}

FrameD exact_code_frame(unsigned code, unsigned levels, double ratio) {
    return exact_frame_from_axis(exact_code_direction(code, levels, ratio));
}

ExactDirectionTable::ExactDirectionTable(float ratio) {
    for (unsigned c = 0; c < 256; ++c) frames_[c] = exact_code_frame(c, 16, double(ratio));
}

ExactDirectionTable16::ExactDirectionTable16(float ratio, unsigned levels) : frames_(levels * levels) {
    for (unsigned c = 0; c < frames_.size(); ++c) frames_[c] = exact_code_frame(c, levels, double(ratio));
}

FrameD exact_block_frame24(const std::array<std::uint32_t, 3>& q0, const std::array<std::uint32_t, 3>& q1) {
    const Vec3d d{double(q1[0]) - double(q0[0]), double(q1[1]) - double(q0[1]), double(q1[2]) - double(q0[2])};
    return exact_frame_from_axis(dot(d, d) > 0 ? unit(d) : Vec3d{1, 0, 0});
}

// The encoder walks every point of a 16-bit file exactly. The table (2.4 MB)
// misses the cache: two thirds of the walk's time waited on its loads, so
// the frames a few steps ahead are prefetched (the codes are known).
void exact_walk(const ExactDirectionTable16& table, FrameD f, Vec3d p, double step, const std::uint16_t* codes,
                std::size_t count, Vec3d* out) {
    constexpr std::size_t kAhead = 8;
    for (std::size_t k = 0; k < count; ++k) {
        if (k + kAhead < count) {
            const char* next = reinterpret_cast<const char*>(&table.frame(codes[k + kAhead]));
            __builtin_prefetch(next), __builtin_prefetch(next + sizeof(FrameD) - 1);
        }
        const FrameD& l = table.frame(codes[k]);
        FrameD g;
        for (int i = 0; i < 3; ++i) {
            const Vec3d v = l.c[i];
            g.c[i] = {v.x * f.c[0].x + v.y * f.c[1].x + v.z * f.c[2].x, v.x * f.c[0].y + v.y * f.c[1].y + v.z * f.c[2].y,
                      v.x * f.c[0].z + v.y * f.c[1].z + v.z * f.c[2].z};
        }
        f = g;
        p = p + step * f.c[0];
        out[k] = p;
    }
}

void exact_walk(const ExactDirectionTable& table, FrameD f, Vec3d p, double step, const std::uint8_t* codes,
                std::size_t count, Vec3d* out) {
    for (std::size_t k = 0; k < count; ++k) {
        f = compose(f, table.frame(codes[k]));
        p = p + step * f.c[0];
        out[k] = p;
    }
}

}  // namespace fiblet::detail
