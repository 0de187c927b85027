#include <algorithm>
#include <cmath>

#include "core/block_geometry.hpp"
#include "core/vec_math.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/error.hpp"

namespace fiblet {
using namespace detail;

namespace {

// unorm16 words of a point in normalized coordinates (computed in double so
// that the rounding to 1/65535 is the only loss).
struct Quantized {
    std::uint16_t q[3];
    Vec3f decoded() const { return {unpack_unorm16(q[0]), unpack_unorm16(q[1]), unpack_unorm16(q[2])}; }
};

Quantized quantize_point(const FftHeader& h, double x, double y, double z) {
    auto one = [&](double v, int axis) {
        const double n = (v + h.offset[axis]) / h.scaling + 0.5;
        return static_cast<std::uint16_t>(std::lround(std::clamp(n, 0.0, 1.0) * 65535.0));
    };
    return {{one(x, 0), one(y, 1), one(z, 2)}};
}

void put_word(std::uint8_t* w, std::uint16_t a, std::uint16_t b) {
    // a | b << 16, most-significant byte first.
    w[0] = std::uint8_t(b >> 8), w[1] = std::uint8_t(b), w[2] = std::uint8_t(a >> 8), w[3] = std::uint8_t(a);
}

}  // namespace

float compute_ratio(double scaling_mm, double step_mm, double min_dot) {
    const double e = scaling_mm / 65536.0;
    // A step no longer than the anchor quantization leaves the first axis
    // arbitrary: take the whole sphere.
    if (!(step_mm > 2 * e)) return 2.0f;
    const double a = std::atan(2 * e / (step_mm - 2 * e));
    const double ratio = 1.0 - std::cos(std::acos(std::clamp(min_dot, -1.0, 1.0)) + a);
    return float(std::clamp(ratio, 1e-4, 2.0));
}

FiberEncoder::FiberEncoder(const FftHeader& header) : header_(header), table_(header.ratio) {}

void FiberEncoder::encode(std::span<const Vec3f> fiber, std::uint32_t fiber_id, std::vector<std::uint8_t>& out,
                          std::vector<Vec3f>* decoded) const {
    const FftHeader& h = header_;
    const std::uint32_t ppb = h.points_per_block, bb = h.block_bytes();
    const std::size_t n_points = fiber.size();
    const std::uint32_t n_blocks = block_count(n_points);
    if (n_blocks > 0xffff)
        throw Error(Errc::unsupported, "fiber " + std::to_string(fiber_id) + " has " + std::to_string(n_points) +
                                           " points: more than 65535 blocks");
    auto emit = [&](Vec3f p) {
        if (decoded) decoded->push_back(h.to_world(p.x, p.y, p.z));
    };
    for (std::uint32_t b = 0; b < n_blocks; ++b) {
        const std::size_t i0 = std::size_t(b) * ppb;
        const auto n = std::uint32_t(std::min<std::size_t>(ppb, n_points - i0));
        const std::size_t base = out.size();
        out.resize(base + bb, 0);
        std::uint8_t* block = &out[base];

        // Anchors: the block's first two points; a one-point block stores the
        // point extrapolated from the previous segment as its second anchor
        // (the tangent a renderer needs), a one-point fiber the point itself.
        const Vec3f p0 = fiber[i0];
        Vec3f p1 = p0;
        if (n >= 2) {
            p1 = fiber[i0 + 1];
        } else if (i0 > 0) {
            p1 = {2 * p0.x - fiber[i0 - 1].x, 2 * p0.y - fiber[i0 - 1].y, 2 * p0.z - fiber[i0 - 1].z};
        }
        const Quantized q0 = quantize_point(h, p0.x, p0.y, p0.z), q1 = quantize_point(h, p1.x, p1.y, p1.z);
        put_word(block + 0, q0.q[0], q0.q[1]);
        put_word(block + 4, q0.q[2], q1.q[0]);
        put_word(block + 8, q1.q[1], q1.q[2]);
        block[12] = std::uint8_t(fiber_id >> 24), block[13] = std::uint8_t(fiber_id >> 16);
        block[14] = std::uint8_t(fiber_id >> 8), block[15] = std::uint8_t(fiber_id);
        block[kBlockFlagsOffset] = std::uint8_t((b > 0 ? kFlagNotFirst : 0) | (b + 1 < n_blocks ? kFlagNotLast : 0) | n);
        block[kBlockIndexOffset] = std::uint8_t(b);  // modulo 256, as the format stores it

        const Vec3f a0 = q0.decoded(), a1 = q1.decoded();
        emit(a0);
        if (n < 2) continue;
        emit(a1);
        // Closed loop: aim each step from the decoded point and frame.
        Frame frame = frame_from_axis(anchor_axis(a0, a1));
        Vec3f p = a1;
        for (std::uint32_t k = 2; k < n; ++k) {
            const Vec3f& src = fiber[i0 + k];
            const Vec3f target{float((double(src.x) + h.offset[0]) / h.scaling + 0.5),
                               float((double(src.y) + h.offset[1]) / h.scaling + 0.5),
                               float((double(src.z) + h.offset[2]) / h.scaling + 0.5)};
            const std::uint8_t code = table_.nearest_code(apply_transposed(frame, target - p));
            block[kBlockDirectionsOffset + k - 2] = code;
            frame = compose(frame, table_.frame(code));
            p = p + h.step * frame.c[0];
            emit(p);
        }
    }
}

}  // namespace fiblet
