// A float64 reference decoder of version-2 .fft files, written from
// formats/fft.md alone, and of version-16 and 17 files (16-bit blocks of a
// fixed size, packed 16-bit blocks), written from formats/fft16.md: it shares no code with the library's decoders (nor
// its frame or direction-table code), so that a test comparing the two
// checks the format, not one implementation against itself. Every formula
// is evaluated in double, so its output is the "exact" decode any
// conforming reader approximates.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace fiblet::test::exact {

struct V3 {
    double x = 0, y = 0, z = 0;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(double s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline V3 unit(V3 a) { return (1.0 / std::sqrt(dot(a, a))) * a; }

// Columns c[0] (the axis), c[1], c[2].
struct Frame3 {
    std::array<V3, 3> c;
};

// Which frame rule: fiblet's, with the fallback helper near ±C, or the
// original decoder's, which has none (formats/fft.md §4).
enum class FrameRule { fiblet, original };

// §4 "Local frames".
inline Frame3 frame_of(V3 axis, FrameRule rule = FrameRule::fiblet) {
    const V3 helper{-0.703023156622, 0.039959276793, 0.71004344758};
    V3 c1 = cross(axis, helper);
    if (rule == FrameRule::fiblet && dot(c1, c1) < 1e-6) c1 = cross(axis, cross(helper, V3{1, 0, 0}));
    c1 = unit(c1);
    return {{axis, c1, unit(cross(axis, c1))}};
}

// F * v and F * L (L's columns expressed in F).
inline V3 apply(const Frame3& f, V3 v) { return v.x * f.c[0] + v.y * f.c[1] + v.z * f.c[2]; }
inline Frame3 compose(const Frame3& f, const Frame3& l) { return {{apply(f, l.c[0]), apply(f, l.c[1]), apply(f, l.c[2])}}; }

// §4 "One byte per direction", decoding side: the code's direction in the
// cap; fft16.md: the same with `levels` levels per diagonal axis.
inline V3 code_direction(unsigned code, double ratio, unsigned levels = 16) {
    const double half = (levels - 1) / 2.0;
    const double q1 = double(code / levels) / half - 1, q2 = double(code % levels) / half - 1;
    const double y = (q1 + q2) / 2, z = (q1 - q2) / 2;
    const V3 d = unit({1 - std::fabs(y) - std::fabs(z), y, z});
    if (y == 0 && z == 0) return {1, 0, 0};  // fft16.md: an odd level count's straight-ahead code
    const double xc = 1 - ratio + ratio * d.x;
    const double lateral = std::sqrt((1 - xc * xc) / (1 - d.x * d.x));
    return unit({xc, d.y * lateral, d.z * lateral});
}

struct Header {
    std::uint8_t version = 0;
    std::uint64_t fibers = 0, points = 0;
    std::uint32_t blocks = 0, points_per_block = 0;
    float scaling = 0, offset[3] = {}, ratio = 0, step = 0, max_error = 0, mean_error = 0;
    std::vector<std::uint64_t> buffer_ends;
    std::size_t block_bytes() const {  // fixed-size blocks (versions 2 and 16)
        return version == 16 ? (24 + 2 * (points_per_block - 2) + 3) / 4 * 4 : (points_per_block + 16 + 3) / 4 * 4;
    }
};

template <class T>
T le(const std::string& b, std::size_t at) {
    if (at + sizeof(T) > b.size()) throw std::runtime_error("exact decoder: file too short");
    T v;
    std::memcpy(&v, b.data() + at, sizeof v);  // the tests run on little-endian hosts
    return v;
}

inline Header read_header(const std::string& b) {
    Header h;
    h.version = le<std::uint8_t>(b, 0);
    if (h.version != 2 && h.version != 16 && h.version != 17) throw std::runtime_error("exact decoder: version " + std::to_string(h.version));
    h.fibers = le<std::uint64_t>(b, 1), h.points = le<std::uint64_t>(b, 9);
    h.blocks = le<std::uint32_t>(b, 17), h.points_per_block = le<std::uint32_t>(b, 21);
    h.scaling = le<float>(b, 25);
    for (int a = 0; a < 3; ++a) h.offset[a] = le<float>(b, 29 + 4 * a);
    h.ratio = le<float>(b, 41), h.step = le<float>(b, 45);
    h.max_error = le<float>(b, 49), h.mean_error = le<float>(b, 53);
    const unsigned buffers = le<std::uint8_t>(b, 57);
    for (unsigned i = 0; i < buffers; ++i) h.buffer_ends.push_back(le<std::uint64_t>(b, 58 + 8 * i));
    return h;
}

// §3: the anchors, three 32-bit words stored most-significant byte first.
inline std::array<double, 6> anchors(const unsigned char* blk) {
    std::array<double, 6> v{};
    for (int w = 0; w < 3; ++w) {
        const std::uint32_t word = std::uint32_t(blk[4 * w]) << 24 | std::uint32_t(blk[4 * w + 1]) << 16 |
                                   std::uint32_t(blk[4 * w + 2]) << 8 | blk[4 * w + 3];
        v[2 * w] = double(word & 0xffff) / 65535.0;
        v[2 * w + 1] = double(word >> 16) / 65535.0;
    }
    return v;
}

// §5: one block's points, normalized coordinates.
inline void decode_block(const unsigned char* blk, const std::vector<Frame3>& table, double step,
                         std::vector<V3>& out, FrameRule rule) {
    const unsigned count = blk[16] & 63;
    const auto a = anchors(blk);
    const V3 a0{a[0], a[1], a[2]}, a1{a[3], a[4], a[5]};
    out.push_back(a0);
    if (count < 2) return;
    out.push_back(a1);
    const V3 d = a1 - a0;
    Frame3 f = frame_of(dot(d, d) > 0 ? unit(d) : V3{1, 0, 0}, rule);
    V3 p = a1;
    for (unsigned k = 0; k + 2 < count; ++k) {
        f = compose(f, table[blk[18 + k]]);
        p = p + step * f.c[0];
        out.push_back(p);
    }
}

struct Decoded {
    Header header;
    std::vector<std::vector<V3>> fibers;  // millimetres
};

// §2: normalized points back to millimetres (scaling, offset of the header).
inline std::vector<V3> to_millimetres(const std::vector<V3>& normalized, const Header& h) {
    std::vector<V3> out;
    out.reserve(normalized.size());
    for (const V3& p : normalized)
        out.push_back({(p.x - 0.5) * double(h.scaling) - double(h.offset[0]),
                       (p.y - 0.5) * double(h.scaling) - double(h.offset[1]),
                       (p.z - 0.5) * double(h.scaling) - double(h.offset[2])});
    return out;
}

// fft16.md, version 17: one packed block of `count` points at `blk` (18
// anchor bytes, unorm24 least significant byte first, then 15-bit codes,
// least significant bit first); returns its size in bytes.
inline std::size_t decode_packed_block(const unsigned char* blk, unsigned count, const std::vector<Frame3>& table,
                                       double step, std::vector<V3>& out) {
    double q[6];
    for (int i = 0; i < 6; ++i) q[i] = double(blk[3 * i] | blk[3 * i + 1] << 8 | blk[3 * i + 2] << 16);
    const V3 a0{q[0] / 16777215.0, q[1] / 16777215.0, q[2] / 16777215.0};
    const V3 a1{q[3] / 16777215.0, q[4] / 16777215.0, q[5] / 16777215.0};
    out.push_back(a0);
    if (count < 2) return 18;
    out.push_back(a1);
    const V3 d{q[3] - q[0], q[4] - q[1], q[5] - q[2]};  // the first axis: of the integer difference
    Frame3 f = frame_of(dot(d, d) > 0 ? unit(d) : V3{1, 0, 0});
    V3 p = a1;
    for (unsigned k = 0; k + 2 < count; ++k) {
        unsigned code = 0;
        for (unsigned bit = 0; bit < 15; ++bit) {
            const unsigned at = 15 * k + bit;
            code |= unsigned(blk[18 + at / 8] >> (at % 8) & 1) << bit;
        }
        f = compose(f, table.at(code));
        p = p + step * f.c[0];
        out.push_back(p);
    }
    return 18 + (15 * (count - 2) + 7) / 8;  // count >= 2 here
}

// fft16.md, version 16: one fixed-size block (18 anchor bytes, unorm24
// least significant byte first; fiber id; u16 flags/count; u16 codes);
// returns its point count. The first axis is that of the decoded anchors.
inline unsigned decode_block16(const unsigned char* blk, const std::vector<Frame3>& table, double step,
                               std::vector<V3>& out) {
    double a[6];
    for (int i = 0; i < 6; ++i) a[i] = double(blk[3 * i] | blk[3 * i + 1] << 8 | blk[3 * i + 2] << 16) / 16777215.0;
    const unsigned count = (blk[22] | blk[23] << 8) & 0x3fff;
    const V3 a0{a[0], a[1], a[2]}, a1{a[3], a[4], a[5]};
    out.push_back(a0);
    if (count < 2) return count;
    out.push_back(a1);
    const V3 d = a1 - a0;
    Frame3 f = frame_of(dot(d, d) > 0 ? unit(d) : V3{1, 0, 0});
    V3 p = a1;
    for (unsigned k = 0; k + 2 < count; ++k) {
        f = compose(f, table.at(blk[24 + 2 * k] | blk[25 + 2 * k] << 8));
        p = p + step * f.c[0];
        out.push_back(p);
    }
    return count;
}

// §6: the payload of trailer chunk `tag`, empty when the file has none.
inline std::string trailer_chunk(const std::string& bytes, const char* tag) {
    if (bytes.size() < 16 || bytes.compare(bytes.size() - 8, 8, "FIBLETX1") != 0) return {};
    for (std::size_t at = le<std::uint64_t>(bytes, bytes.size() - 16); at + 16 <= bytes.size() - 16;) {
        const std::uint64_t size = le<std::uint64_t>(bytes, at + 8);
        if (bytes.compare(at, 4, tag) == 0) return bytes.substr(at + 16, size);
        at += 16 + size;
    }
    return {};
}


// fft-ends.md: the fiber's last point moved to p_prev + f (p_last - p_prev),
// f = q / 65535, where the chunk gives q < 65535 and the fiber's last block
// holds three points or more.
inline void apply_end(std::vector<V3>& fiber, const std::string& ends, std::uint64_t i, unsigned last_block_points) {
    if (ends.size() < 2 * (i + 1) || last_block_points < 3 || fiber.size() < 2) return;
    const unsigned q = unsigned((unsigned char)ends[2 * i]) | unsigned((unsigned char)ends[2 * i + 1]) << 8;
    if (q == 65535) return;
    const V3 prev = fiber[fiber.size() - 2], last = fiber.back();
    fiber.back() = prev + (double(q) / 65535.0) * (last - prev);
}

// The whole file: fibers in LUT order, points mapped back to millimetres
// (§2); version 2 with either frame rule.
inline Decoded decode(const std::string& bytes, FrameRule rule = FrameRule::fiblet) {
    Decoded d;
    Header& h = d.header = read_header(bytes);
    const std::string ends = trailer_chunk(bytes, "ENDS");
    if (h.version == 17) {
        // fft16.md: 181 levels; the LUT's second word is the fiber's point
        // count; packed blocks follow each other, fiber after fiber.
        std::vector<Frame3> table(181 * 181);
        for (unsigned c = 0; c < table.size(); ++c) table[c] = frame_of(code_direction(c, h.ratio, 181));
        const std::size_t lut = 58 + 8 * h.buffer_ends.size();
        std::size_t at = lut + 8 * h.fibers;
        std::vector<V3> normalized;
        for (std::uint64_t i = 0; i < h.fibers; ++i) {
            const auto x = le<std::uint32_t>(bytes, lut + 8 * i), points = le<std::uint32_t>(bytes, lut + 8 * i + 4);
            const unsigned count = x & 0xffff;
            normalized.clear();
            unsigned n = 0;
            for (unsigned b = 0; b < count; ++b) {
                n = b + 1 < count ? h.points_per_block : points - b * h.points_per_block;
                if (at + 18 + (n > 2 ? (15 * (n - 2) + 7) / 8 : 0) > bytes.size())
                    throw std::runtime_error("exact decoder: block past the end");
                at += decode_packed_block(reinterpret_cast<const unsigned char*>(bytes.data()) + at, n, table,
                                          double(h.step), normalized);
            }
            d.fibers.push_back(to_millimetres(normalized, h));
            apply_end(d.fibers.back(), ends, i, n);
        }
        return d;
    }
    // Versions 2 and 16: fixed-size blocks found through the LUT.
    const unsigned levels = h.version == 16 ? 256 : 16;
    std::vector<Frame3> table(levels * levels);
    for (unsigned c = 0; c < table.size(); ++c) table[c] = frame_of(code_direction(c, h.ratio, levels), rule);
    const std::size_t lut = 58 + 8 * h.buffer_ends.size(), blocks = lut + 8 * h.fibers;
    std::vector<V3> normalized;
    for (std::uint64_t i = 0; i < h.fibers; ++i) {
        const auto x = le<std::uint32_t>(bytes, lut + 8 * i), y = le<std::uint32_t>(bytes, lut + 8 * i + 4);
        const unsigned buffer = x >> 16, count = x & 0xffff;
        const std::uint64_t first = y + (buffer > 0 ? h.buffer_ends.at(buffer - 1) : 0);
        normalized.clear();
        unsigned last_block_points = 0;
        for (unsigned b = 0; b < count; ++b) {
            const std::size_t at = blocks + (first + b) * h.block_bytes();
            if (at + h.block_bytes() > bytes.size()) throw std::runtime_error("exact decoder: block past the end");
            const auto* blk = reinterpret_cast<const unsigned char*>(bytes.data()) + at;
            if (h.version == 16) {
                last_block_points = decode_block16(blk, table, double(h.step), normalized);
            } else {
                decode_block(blk, table, double(h.step), normalized, rule);
                last_block_points = blk[16] & 63;
            }
        }
        d.fibers.push_back(to_millimetres(normalized, h));
        if (count > 0) apply_end(d.fibers.back(), ends, i, last_block_points);
    }
    return d;
}


}  // namespace fiblet::test::exact
