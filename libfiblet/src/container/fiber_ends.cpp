#include "fiblet/fiber_ends.hpp"

#include "core/bytes.hpp"
#include "fiblet/error.hpp"

namespace fiblet {

TrailerChunk make_fiber_ends_chunk(std::span<const std::uint16_t> fractions) {
    TrailerChunk c{kFiberEndsTag, std::vector<std::uint8_t>(2 * fractions.size())};
    for (std::size_t i = 0; i < fractions.size(); ++i) {
        c.payload[2 * i] = std::uint8_t(fractions[i]);
        c.payload[2 * i + 1] = std::uint8_t(fractions[i] >> 8);
    }
    return c;
}

FiberEndFractions parse_fiber_ends_chunk(const TrailerChunk& chunk, std::uint64_t fibers, const std::string& path) {
    if (chunk.payload.size() != 2 * fibers)
        throw Error(Errc::fft_format, path + ": ENDS chunk of " + std::to_string(chunk.payload.size()) +
                                          " bytes, expected 2 per fiber (" + std::to_string(2 * fibers) + ")");
    FiberEndFractions f(fibers);
    for (std::uint64_t i = 0; i < fibers; ++i) f[i] = detail::get_le<std::uint16_t>(&chunk.payload[2 * i]);
    return f;
}

void apply_fiber_ends(const FftHeader& h, const FiberEndFractions& fractions, const std::uint8_t* blocks,
                      std::size_t count, float* xyz) {
    const std::size_t bb = h.block_bytes();
    std::size_t point = 0;
    for (std::size_t b = 0; b < count; ++b) {
        const std::uint8_t* block = blocks + b * bb;
        const BlockFlags flags = block_flags(h, block);
        point += flags.point_count;
        if (!flags.last || !end_fraction_applies(flags.point_count)) continue;
        const std::uint32_t id = flags.fiber_id;
        if (id >= fractions.size() || fractions[id] == kWholeLastStep) continue;
        float* last = xyz + 3 * (point - 1);
        const float* prev = last - 3;
        const Vec3f p = place_end_point({prev[0], prev[1], prev[2]}, {last[0], last[1], last[2]}, fractions[id]);
        last[0] = p.x, last[1] = p.y, last[2] = p.z;
    }
}

}  // namespace fiblet
