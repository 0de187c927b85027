// The scalar reference decoder: one block after the other, one point after
// the other, exactly as formats/fft.md describes it.
#include <cmath>
#include <string>

#include "core/block_geometry.hpp"
#include "core/vec_math.hpp"
#include "decode/decode_kernels.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"

namespace fiblet {
using namespace detail;

void detail::put_frame_row(const Frame& f, float* row) {
    for (int col = 0; col < 3; ++col) {
        row[3 * col + 0] = f.c[col].x;
        row[3 * col + 1] = f.c[col].y;
        row[3 * col + 2] = f.c[col].z;
    }
}

DecodeContext::DecodeContext(const FftHeader& h) : header(h), table(h.ratio), frame_rows16(frame_rows16_of(h)) {
    for (int k = 0; k < 256; ++k) put_frame_row(table.frame(std::uint8_t(k)), &frame_rows[16 * k]);
}

DecodeContext::DecodeContext(const FftFile& file) : DecodeContext(file.header()) {
    end_fractions = file.end_fractions();
}

std::size_t count_block_points(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count) {
    const std::uint32_t bb = ctx.header.block_bytes();
    std::size_t total = 0;
    for (std::size_t b = 0; b < count; ++b) {
        const std::uint32_t n = block_flags(ctx.header, blocks + b * bb).point_count;
        if (n == 0 || n > ctx.header.points_per_block)
            throw Error(Errc::fft_format, "block holds " + std::to_string(n) + " points (allowed 1.." +
                                              std::to_string(ctx.header.points_per_block) + ")");
        total += n;
    }
    return total;
}

std::size_t decode_blocks_scalar(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count,
                                 float* xyz) {
    const FftHeader& h = ctx.header;
    const std::uint32_t bb = h.block_bytes();
    float* out = xyz;
    for (std::size_t b = 0; b < count; ++b) {
        const BlockView block{blocks + b * bb};
        const std::uint32_t n = block.point_count();
        const BlockStart start = block_start(block);
        auto emit = [&](Vec3f p) {
            const Vec3f w = h.to_world(p.x, p.y, p.z);
            *out++ = w.x, *out++ = w.y, *out++ = w.z;
        };
        emit(start.anchor0);
        if (n < 2) continue;
        emit(start.anchor1);
        Frame frame = start.frame;
        Vec3f p = start.anchor1;
        const std::uint8_t* codes = block.directions();
        for (std::uint32_t k = 2; k < n; ++k) {
            frame = compose(frame, ctx.table.frame(codes[k - 2]));
            p = p + h.step * frame.c[0];
            emit(p);
        }
    }
    return std::size_t(out - xyz) / 3;
}

}  // namespace fiblet
