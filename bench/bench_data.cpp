#include "bench_data.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "fiblet/direction_code.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/tck.hpp"

namespace fiblet::bench {

void read_tck(const std::string& path, Tractogram& out) {
    TckReader reader(path);
    out.xyz.clear();
    out.offsets.assign(1, 0);
    std::vector<Vec3f> fiber;
    while (reader.next(fiber)) {
        const float* p = &fiber.data()->x;
        out.xyz.insert(out.xyz.end(), p, p + 3 * fiber.size());
        out.offsets.push_back(out.offsets.back() + fiber.size());
    }
}

std::string default_bench_tck() {
    if (const char* p = std::getenv("FIBLET_BENCH_TCK")) return p;
    return std::string(FIBLET_SHARED_DIR) + "/data/small-ifod1.tck";
}

PointErrors point_errors(const std::vector<float>& a, const std::vector<float>& b) {
    PointErrors e;
    const std::size_t n = std::min(a.size(), b.size()) / 3;
    double sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const double dx = double(a[3 * i]) - b[3 * i], dy = double(a[3 * i + 1]) - b[3 * i + 1],
                     dz = double(a[3 * i + 2]) - b[3 * i + 2];
        const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
        e.max_mm = std::max(e.max_mm, d);
        sum += d;
    }
    e.mean_mm = n ? sum / double(n) : 0.0;
    return e;
}

namespace {

#if defined(__x86_64__)
__attribute__((target("avx,f16c"))) void to_half_f16c(const float* in, std::uint16_t* out, std::size_t n) {
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8)
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i),
                         _mm256_cvtps_ph(_mm256_loadu_ps(in + i), _MM_FROUND_TO_NEAREST_INT));
    for (; i < n; ++i) out[i] = _cvtss_sh(in[i], _MM_FROUND_TO_NEAREST_INT);
}
__attribute__((target("avx,f16c"))) void from_half_f16c(const std::uint16_t* in, float* out, std::size_t n) {
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8)
        _mm256_storeu_ps(out + i, _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(in + i))));
    for (; i < n; ++i) out[i] = _cvtsh_ss(in[i]);
}
bool have_f16c() { return __builtin_cpu_supports("f16c") && __builtin_cpu_supports("avx"); }
#endif

}  // namespace

void to_half(const float* in, std::uint16_t* out, std::size_t n) {
#if defined(__x86_64__)
    if (have_f16c()) return to_half_f16c(in, out, n);
#endif
    for (std::size_t i = 0; i < n; ++i) {
        const _Float16 h = static_cast<_Float16>(in[i]);
        std::memcpy(&out[i], &h, 2);
    }
}

void from_half(const std::uint16_t* in, float* out, std::size_t n) {
#if defined(__x86_64__)
    if (have_f16c()) return from_half_f16c(in, out, n);
#endif
    for (std::size_t i = 0; i < n; ++i) {
        _Float16 h;
        std::memcpy(&h, &in[i], 2);
        out[i] = float(h);
    }
}

namespace {

// The reference decoder's float operations, on world coordinates.
Vec3f add(Vec3f a, Vec3f b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec3f scale(float s, Vec3f a) { return {s * a.x, s * a.y, s * a.z}; }
float dot(Vec3f a, Vec3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3f apply(const Frame& f, Vec3f v) {
    return {f.c[0].x * v.x + f.c[1].x * v.y + f.c[2].x * v.z, f.c[0].y * v.x + f.c[1].y * v.y + f.c[2].y * v.z,
            f.c[0].z * v.x + f.c[1].z * v.y + f.c[2].z * v.z};
}
Frame compose(const Frame& f, const Frame& l) { return {{apply(f, l.c[0]), apply(f, l.c[1]), apply(f, l.c[2])}}; }
Frame first_frame(Vec3f a0, Vec3f a1) {
    const Vec3f d{a1.x - a0.x, a1.y - a0.y, a1.z - a0.z};
    const float n2 = dot(d, d);
    return frame_from_axis(n2 > 0 ? scale(1.0f / std::sqrt(n2), d) : Vec3f{1, 0, 0});
}

template <class T>
void put(std::vector<std::uint8_t>& out, const T& v) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    out.insert(out.end(), p, p + sizeof v);
}

}  // namespace

SequentialCoded encode_sequential(const Tractogram& t) {
    SequentialCoded c;
    c.fibers = t.fibers(), c.points = t.points();
    // Step: mean segment length; cap: the sharpest turn (as compute_ratio).
    double length = 0, min_dot = 1;
    std::size_t segments = 0;
    auto at = [&](std::size_t i) { return Vec3f{t.xyz[3 * i], t.xyz[3 * i + 1], t.xyz[3 * i + 2]}; };
    for (std::size_t f = 0; f < t.fibers(); ++f)
        for (std::size_t i = t.offsets[f] + 1; i < t.offsets[f + 1]; ++i) {
            const Vec3f a = at(i - 1), b = at(i);
            const double dx = double(b.x) - a.x, dy = double(b.y) - a.y, dz = double(b.z) - a.z;
            const double l = std::sqrt(dx * dx + dy * dy + dz * dz);
            length += l, ++segments;
            if (i >= t.offsets[f] + 2 && l > 0) {
                const Vec3f z = at(i - 2);
                const double ex = double(a.x) - z.x, ey = double(a.y) - z.y, ez = double(a.z) - z.z;
                const double m = std::sqrt(ex * ex + ey * ey + ez * ez);
                if (m > 0) min_dot = std::min(min_dot, (dx * ex + dy * ey + dz * ez) / (l * m));
            }
        }
    c.step_mm = segments ? float(length / double(segments)) : 0.0f;
    // Anchors are float32: no anchor quantization term.
    c.ratio = compute_ratio(1e-9, std::max(double(c.step_mm), 1e-6), min_dot);
    const DirectionTable table(c.ratio);
    for (std::size_t f = 0; f < t.fibers(); ++f) {
        const std::size_t i0 = t.offsets[f], n = t.offsets[f + 1] - i0;
        put(c.bytes, std::uint32_t(n));
        for (std::size_t i = i0; i < i0 + std::min<std::size_t>(n, 2); ++i) put(c.bytes, at(i));
        if (n < 3) continue;
        Frame frame = first_frame(at(i0), at(i0 + 1));
        Vec3f p = at(i0 + 1);
        for (std::size_t i = i0 + 2; i < i0 + n; ++i) {
            const Vec3f target = at(i), d{target.x - p.x, target.y - p.y, target.z - p.z};
            const Vec3f local{dot(frame.c[0], d), dot(frame.c[1], d), dot(frame.c[2], d)};
            const std::uint8_t code = table.nearest_code(local);
            c.bytes.push_back(code);
            frame = compose(frame, table.frame(code));
            p = add(p, scale(c.step_mm, frame.c[0]));
        }
    }
    return c;
}

void decode_sequential(const SequentialCoded& c, float* out) {
    const DirectionTable table(c.ratio);
    const std::uint8_t* in = c.bytes.data();
    for (std::size_t f = 0; f < c.fibers; ++f) {
        std::uint32_t n;
        std::memcpy(&n, in, 4);
        in += 4;
        const std::size_t anchors = std::min<std::uint32_t>(n, 2);
        std::memcpy(out, in, 12 * anchors);
        in += 12 * anchors, out += 3 * anchors;
        if (n < 3) continue;
        const Vec3f a0{out[-6], out[-5], out[-4]};
        Vec3f p{out[-3], out[-2], out[-1]};
        Frame frame = first_frame(a0, p);
        for (std::uint32_t k = 2; k < n; ++k) {
            frame = compose(frame, table.frame(*in++));
            p = add(p, scale(c.step_mm, frame.c[0]));
            *out++ = p.x, *out++ = p.y, *out++ = p.z;
        }
    }
}

}  // namespace fiblet::bench

// ---- fixture ----
#include <stdlib.h>

#include <filesystem>
#include <stdexcept>

#include "bench_fixture.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/fft_file.hpp"

namespace fiblet::bench {

Fixture::Fixture() : tck(default_bench_tck()) {
    std::string tmpl = std::filesystem::temp_directory_path().string() + "/fiblet-bench-XXXXXX";
    if (!::mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
    dir = tmpl;
    fft = dir + "/bench.fft";
    compress_file(tck, fft, {});
    read_tck(tck, tractogram);
    const FftFile file(fft);
    header = file.header();
    blocks = file.read_blocks(0, header.blocks);
    points = header.points;
}

Fixture::~Fixture() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
}

const Fixture& fixture() {
    static const Fixture f;
    return f;
}

}  // namespace fiblet::bench
