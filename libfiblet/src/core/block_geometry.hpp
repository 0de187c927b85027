// Internal: the state a block starts from (its two anchors and first frame),
// shared by the encoder and every decoder so that they agree bit for bit.
#pragma once

#include "core/vec_math.hpp"
#include "fiblet/fft_format.hpp"

namespace fiblet::detail {

struct BlockStart {
    Vec3f anchor0, anchor1;  // normalized coordinates
    Frame frame;             // frame_from_axis(normalize(anchor1 - anchor0))
};

// The first frame's axis; coinciding anchors (a zero step, possible in
// degenerate input) fall back to +x instead of producing NaN.
inline Vec3f anchor_axis(Vec3f a0, Vec3f a1) {
    const Vec3f d = a1 - a0;
    const float n2 = dot(d, d);
    return n2 > 0.0f ? (1.0f / std::sqrt(n2)) * d : Vec3f{1.0f, 0.0f, 0.0f};
}

inline BlockStart block_start(const BlockView& block) {
    const auto a = block.anchors_normalized();
    BlockStart s{{a[0], a[1], a[2]}, {a[3], a[4], a[5]}, {}};
    s.frame = frame_from_axis(anchor_axis(s.anchor0, s.anchor1));
    return s;
}

}  // namespace fiblet::detail
