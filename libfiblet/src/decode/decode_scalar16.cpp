// The scalar reference decoder of 16-bit files (formats/fft16.md): the same
// walk as decode_scalar.cpp with unorm24 anchors and 16-bit codes.
#include "fiblet/decode.hpp"

#include <bit>
#include <cmath>
#include <map>
#include <mutex>
#include <string>
#include <utility>

#include "core/block_geometry.hpp"
#include "core/vec_math.hpp"
#include "decode/decode_kernels.hpp"
#include "fiblet/error.hpp"
#include "container/packed_blocks16.hpp"

namespace fiblet {
using namespace detail;

namespace {

// A 16-bit file's table and its SIMD rows, shared by every DecodeContext of
// the same ratio and levels: they take milliseconds and 6 MiB to make, and
// a decode makes a context per thread and chunk. Held while some context
// holds them, and the last one made until another replaces it: a command
// proves a file's points finite and then decodes it, Python loads a file
// again, each with the table of the call before.
struct Tables16 {
    Tables16(float ratio, unsigned levels) : table(ratio, levels) {
        for (unsigned k = 0; k < 65536; ++k) put_frame_row(table.frame(std::uint16_t(k)), &rows.rows[16 * k]);
    }
    DirectionTable16 table;
    DecodeContext::FrameRows16 rows{};  // padding zero, as the 8-bit rows
};

std::shared_ptr<const Tables16> tables16(const FftHeader& header) {
    static std::mutex mutex;
    static std::map<std::pair<std::uint32_t, unsigned>, std::weak_ptr<const Tables16>> made;
    const std::pair key{std::bit_cast<std::uint32_t>(header.ratio), header.code_levels()};
    static std::shared_ptr<const Tables16> last;
    const std::lock_guard lock(mutex);
    if (auto t = made[key].lock()) return last = t;
    last.reset();  // before the next is made: at most two alive here
    std::erase_if(made, [](const auto& entry) { return entry.second.expired(); });
    auto t = std::shared_ptr<const Tables16>(new Tables16(header.ratio, header.code_levels()));  // over-aligned
    made[key] = t;
    return last = t;
}

}  // namespace

std::shared_ptr<const DirectionTable16> make_direction_table16(const FftHeader& header) {
    if (header.direction_bits() != 16) return nullptr;
    auto t = tables16(header);
    return {t, &t->table};
}

std::shared_ptr<const DecodeContext::FrameRows16> detail::frame_rows16_of(const FftHeader& header) {
    if (header.direction_bits() != 16) return nullptr;
    auto t = tables16(header);
    return {t, &t->rows};
}

std::size_t decode_blocks_scalar16(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count,
                                   float* xyz) {
    const FftHeader& h = ctx.header;
    if (!ctx.table16) throw Error(Errc::invalid_argument, "decode_blocks_scalar16 on a file without 16-bit codes");
    const DirectionTable16& table = *ctx.table16;
    const std::uint32_t bb = h.block_bytes();
    float* out = xyz;
    for (std::size_t b = 0; b < count; ++b) {
        const BlockView16 block{blocks + b * bb};
        const std::uint32_t n = block.point_count();
        const auto a = block.anchors_normalized();
        const Vec3f a0{a[0], a[1], a[2]}, a1{a[3], a[4], a[5]};
        auto emit = [&](Vec3f p) {
            const Vec3f w = h.to_world(p.x, p.y, p.z);
            *out++ = w.x, *out++ = w.y, *out++ = w.z;
        };
        emit(a0);
        if (n < 2) continue;
        emit(a1);
        Frame frame = frame_from_axis(h.packed() ? packed16_anchor_axis(block) : anchor_axis(a0, a1));
        Vec3f p = a1;
        for (std::uint32_t k = 2; k < n; ++k) {
            frame = compose(frame, table.frame(block.code(k - 2)));
            p = p + h.step * frame.c[0];
            emit(p);
        }
    }
    return std::size_t(out - xyz) / 3;
}

}  // namespace fiblet
