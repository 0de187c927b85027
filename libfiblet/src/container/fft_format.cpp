#include "fiblet/fft_format.hpp"

#include <algorithm>
#include <cmath>

#include "core/bytes.hpp"

namespace fiblet {
using detail::put_le;

std::uint16_t pack_unorm16(float v) {
    const float c = std::clamp(v, 0.0f, 1.0f);  // NaN never reaches here: inputs are validated
    return static_cast<std::uint16_t>(std::lround(c * 65535.0f));
}

std::vector<std::uint8_t> serialize_fft_header(const FftHeader& h) {
    std::vector<std::uint8_t> out;
    out.reserve(h.lut_offset());
    put_le(out, h.version);
    put_le(out, h.fibers);
    put_le(out, h.points);
    put_le(out, h.blocks);
    put_le(out, h.points_per_block);
    put_le(out, h.scaling);
    for (float o : h.offset) put_le(out, o);
    put_le(out, h.ratio);
    put_le(out, h.step);
    put_le(out, h.max_error_mm);
    put_le(out, h.mean_error_mm);
    put_le(out, static_cast<std::uint8_t>(h.buffer_ends.size()));
    for (std::uint64_t e : h.buffer_ends) put_le(out, e);
    return out;
}

void append_trailer_chunk_head(std::vector<std::uint8_t>& out, const TrailerChunk& c) {
    out.insert(out.end(), c.tag.begin(), c.tag.end());
    put_le(out, std::uint32_t{0});
    put_le(out, std::uint64_t{c.payload.size()});
}

void append_trailer_chunk(std::vector<std::uint8_t>& out, const TrailerChunk& c) {
    append_trailer_chunk_head(out, c);
    out.insert(out.end(), c.payload.begin(), c.payload.end());
}

std::vector<std::uint8_t> serialize_trailer(const std::vector<TrailerChunk>& chunks, std::uint64_t trailer_offset) {
    std::vector<std::uint8_t> out;
    std::size_t size = kTrailerFooterBytes;  // reserved whole, as the DATA chunk may be large
    for (const TrailerChunk& c : chunks) size += 16 + c.payload.size();
    out.reserve(size);
    for (const TrailerChunk& c : chunks) append_trailer_chunk(out, c);
    put_le(out, trailer_offset);
    out.insert(out.end(), std::begin(kTrailerMagic), std::end(kTrailerMagic));
    return out;
}

TrailerChunk make_properties_chunk(const std::vector<std::pair<std::string, std::string>>& properties) {
    TrailerChunk c{kPropertiesTag, {}};
    auto put_string = [&](const std::string& s) {
        put_le(c.payload, std::uint32_t(s.size()));
        c.payload.insert(c.payload.end(), s.begin(), s.end());
    };
    for (const auto& [k, v] : properties) put_string(k), put_string(v);
    return c;
}

}  // namespace fiblet
