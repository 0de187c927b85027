#include "container/fft_trailer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/bytes.hpp"
#include "fiblet/block_index.hpp"
#include "fiblet/checksum.hpp"
#include "fiblet/error.hpp"
#include "fiblet/streamline_data_chunk.hpp"
#include "index/index_chunk.hpp"

namespace fiblet::detail {

namespace {

std::string tag_name(const std::array<char, 4>& tag) {
    std::string s;
    for (char c : tag) s += (c >= 0x20 && c < 0x7f) ? c : '?';
    return s;
}

// Chunks fiblet reads are loaded whole up to a bound that keeps memory in
// check (a BIDX chunk costs ~4 bytes a block: 64 MiB is 16 M blocks; ENDS
// holds 2 bytes a fiber, its bound grows with the fiber count); unknown
// chunks above 16 MiB are skipped (they are still covered by the trailer hash).
constexpr std::uint64_t kMaxKnownChunk = 64u << 20, kMaxUnknownChunk = 16u << 20;

bool is_known(const std::array<char, 4>& tag) {
    return tag == kPropertiesTag || tag == kResampledTag || tag == kChecksumTag || tag == kBlockIndexTag ||
           tag == kFiberEndsTag || tag == kStreamlineDataTag;
}

std::uint64_t max_known_size(const std::array<char, 4>& tag, std::uint64_t fibers) {
    // DATA holds what its source held (per point, any type): only the file bounds it.
    if (tag == kStreamlineDataTag) return std::numeric_limits<std::uint64_t>::max();
    return tag == kFiberEndsTag ? std::max(kMaxKnownChunk, 2 * fibers) : kMaxKnownChunk;
}

// Hashes a chunk payload too large to keep, a slice at a time.
void hash_unloaded(const ReadAt& read_at, std::uint64_t at, std::uint64_t size, Xxh64Stream& hash) {
    std::vector<std::uint8_t> slice;
    for (std::uint64_t done = 0; done < size;) {
        slice.resize(std::size_t(std::min<std::uint64_t>(1u << 20, size - done)));
        read_at(slice.data(), slice.size(), at + done);
        hash.update(slice.data(), slice.size());
        done += slice.size();
    }
}

}  // namespace

TrailerChunks read_trailer_chunks(const ReadAt& read_at, std::uint64_t end, std::uint64_t logical_size,
                                  std::uint64_t fibers, const std::string& name) {
    TrailerChunks t;
    if (logical_size <= end) return t;  // nothing after the blocks: an official-encoder file
    auto damaged = [&](const std::string& what) {
        throw Error(Errc::checksum,
                    name + ": damaged trailer: " + what +
                        " (the bytes after the last block are not a complete fiblet trailer; the blocks can be read without it)",
                    Remedy::ignore_trailer);
    };
    if (logical_size - end < kTrailerFooterBytes)
        damaged(std::to_string(logical_size - end) + " bytes after the last block, too few for a footer");
    std::uint8_t footer[kTrailerFooterBytes];
    read_at(footer, sizeof footer, logical_size - sizeof footer);
    if (std::memcmp(footer + 8, kTrailerMagic, 8) != 0) damaged("no FIBLETX1 footer at the end of the file");
    if (get_le<std::uint64_t>(footer) != end)
        damaged("the footer says the trailer starts at byte " + std::to_string(get_le<std::uint64_t>(footer)) +
                ", the blocks end at byte " + std::to_string(end));
    const std::uint64_t stop = logical_size - kTrailerFooterBytes;
    Xxh64Stream before_checksum;
    for (std::uint64_t pos = end; pos < stop;) {
        std::uint8_t head[16];
        if (stop - pos < sizeof head) damaged("truncated chunk header at byte " + std::to_string(pos));
        read_at(head, sizeof head, pos);
        TrailerChunk chunk;
        std::memcpy(chunk.tag.data(), head, 4);
        const std::uint32_t flags = get_le<std::uint32_t>(head + 4);
        const std::uint64_t size = get_le<std::uint64_t>(head + 8);
        const std::string what = "chunk " + tag_name(chunk.tag) + " at byte " + std::to_string(pos);
        if (flags != 0) damaged(what + " has flags " + std::to_string(flags) + " (0 expected)");
        if (size > stop - pos - sizeof head) damaged(what + " runs past the footer");
        if (t.checksum_chunk_at != 0) damaged(what + " follows the CSUM chunk (which must be last)");
        const bool known = is_known(chunk.tag);
        if (known && size > max_known_size(chunk.tag, fibers))
            damaged(what + " of " + std::to_string(size) + " bytes (at most " +
                    std::to_string(max_known_size(chunk.tag, fibers)) + ")");
        const bool is_checksum = chunk.tag == kChecksumTag;
        if (is_checksum) t.checksum_chunk_at = pos;
        else before_checksum.update(head, sizeof head);  // CSUM's trailerHash covers the chunks before it
        if (known || size <= kMaxUnknownChunk) {
            chunk.payload.resize(size);
            read_at(chunk.payload.data(), size, pos + sizeof head);
            if (!is_checksum) before_checksum.update(chunk.payload.data(), chunk.payload.size());
            t.chunks.push_back(std::move(chunk));
        } else {
            hash_unloaded(read_at, pos + sizeof head, size, before_checksum);
        }
        pos += sizeof head + size;
    }
    if (t.checksum_chunk_at == 0) damaged("no CSUM chunk (every fiblet trailer ends with one)");
    t.hash_before_checksum = before_checksum.digest();
    return t;
}

namespace {

[[noreturn]] void bad_chunk(const std::string& name, const std::array<char, 4>& tag, const std::string& what) {
    throw Error(Errc::fft_format, name + ": not a valid .fft file: " + tag_name(tag) + " chunk: " + what);
}

// PROP: (key, value) string pairs that a .tck header can hold and give back
// (any bytes, NUL included, but a key never holds ':' or a line break).
std::vector<std::pair<std::string, std::string>> parse_properties(const TrailerChunk& c, const std::string& name) {
    const auto& p = c.payload;
    std::size_t pos = 0;
    auto next_string = [&](const char* which) {
        if (p.size() - pos < 4) bad_chunk(name, c.tag, std::string("truncated ") + which + " length");
        const std::uint32_t n = get_le<std::uint32_t>(&p[pos]);
        if (p.size() - pos - 4 < n) bad_chunk(name, c.tag, std::string(which) + " runs past the chunk");
        std::string s(reinterpret_cast<const char*>(&p[pos + 4]), n);
        pos += 4 + std::size_t{n};
        return s;
    };
    std::vector<std::pair<std::string, std::string>> props;
    while (pos < p.size()) {
        std::string key = next_string("key");
        if (key.find_first_of(":\n") != std::string::npos)
            bad_chunk(name, c.tag, "key \"" + key + "\" holds ':' or a line break (no .tck header can)");
        props.emplace_back(std::move(key), next_string("value"));
    }
    return props;
}

// RSMP: the step (mm) variable-step input was resampled to, then (since the
// cubic resampling) the curve it was resampled on. The header's step is that
// step times the decoder step scale, which compress bounds to (0.5, 2); a
// step of 0 or NaN would make a comparison resample forever.
Resampling parse_resampling(const TrailerChunk& c, const FftHeader& h, const std::string& name) {
    const std::size_t size = c.payload.size();
    if (size != 8 && size != 16) bad_chunk(name, c.tag, std::to_string(size) + " bytes (8 or 16 expected)");
    Resampling r{.curve = ResampleCurve::polyline};
    std::memcpy(&r.step_mm, c.payload.data(), 8);
    if (!(std::isfinite(r.step_mm) && r.step_mm > 0)) bad_chunk(name, c.tag, "step is not a positive finite number");
    const double header_step_mm = double(h.step) * double(h.scaling);
    if (!(r.step_mm >= header_step_mm * 0.499 && r.step_mm <= header_step_mm * 2.001))
        bad_chunk(name, c.tag,
                  "step " + std::to_string(r.step_mm) + " mm disagrees with the header's " +
                      std::to_string(header_step_mm) + " mm");
    if (size == 16) {
        std::uint32_t curve, reserved;
        std::memcpy(&curve, c.payload.data() + 8, 4);
        std::memcpy(&reserved, c.payload.data() + 12, 4);
        if (curve > std::uint32_t(ResampleCurve::rounded_keeping_length) || reserved != 0)
            bad_chunk(name, c.tag, "unknown resampling curve " + std::to_string(curve) + "/" + std::to_string(reserved));
        r.curve = ResampleCurve(curve);
    }
    r.stretch = decoder_stretch(h.step, h.scaling, r.step_mm);
    return r;
}

}  // namespace

TrailerValues validate_trailer_chunks(const std::vector<TrailerChunk>& chunks, const FftHeader& header,
                                      const std::string& name) {
    TrailerValues v;
    std::vector<std::array<char, 4>> seen;
    for (const TrailerChunk& c : chunks) {
        if (!is_known(c.tag)) continue;
        for (const auto& s : seen)
            if (s == c.tag) bad_chunk(name, c.tag, "appears more than once");
        seen.push_back(c.tag);
        if (c.tag == kPropertiesTag) v.properties = parse_properties(c, name);
        else if (c.tag == kResampledTag) v.resampling = parse_resampling(c, header, name);
        else if (c.tag == kBlockIndexTag) (void)parse_index_chunk(c.payload, header, name);
        else if (c.tag == kFiberEndsTag)
            v.end_fractions = std::make_shared<const FiberEndFractions>(parse_fiber_ends_chunk(c, header.fibers, name));
        else if (c.tag == kStreamlineDataTag)
            v.fields = std::make_shared<const std::vector<StreamlineField>>(
                parse_streamline_data_chunk(c, header.fibers, header.points, name));
    }
    return v;
}

}  // namespace fiblet::detail
