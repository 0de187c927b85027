// Shared by the viewer tests: one headless OpenGL context for the test
// program (tests skip when none can be made), scenes made from shared data
// or compressed on the fly, and the CPU references the GPU is checked against.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "fiblet/view.hpp"
#include "scene/gpu_programs.hpp"
#include "scene/gpu_scene.hpp"
#include "gl/headless_context.hpp"
#include "test_util.hpp"

namespace fiblet::test {

struct ViewerGl {
    std::unique_ptr<viewer::HeadlessContext> context;
    std::unique_ptr<viewer::GpuPrograms> programs;
    std::string error;
};

// The unit ray through the centre of pixel (x, y) (rows from the top) of
// view.hpp's camera: what the CPU references trace.
inline std::array<double, 3> camera_pixel_ray(const Camera& cam, int x, int y, int w, int h) {
    auto unit = [](double a, double b, double c) {
        const double n = std::sqrt(a * a + b * b + c * c);
        return std::array<double, 3>{a / n, b / n, c / n};
    };
    const auto fwd = unit(cam.target.x - cam.position.x, cam.target.y - cam.position.y, cam.target.z - cam.position.z);
    const auto right = unit(fwd[1] * cam.up.z - fwd[2] * cam.up.y, fwd[2] * cam.up.x - fwd[0] * cam.up.z,
                            fwd[0] * cam.up.y - fwd[1] * cam.up.x);
    const std::array<double, 3> up{right[1] * fwd[2] - right[2] * fwd[1], right[2] * fwd[0] - right[0] * fwd[2],
                                   right[0] * fwd[1] - right[1] * fwd[0]};
    const double t = std::tan(double(cam.fov_y_deg) * M_PI / 360.0);
    const double nx = (x + 0.5) / w * 2 - 1, ny = 1 - (y + 0.5) / h * 2;
    return unit(fwd[0] + nx * t * cam.aspect * right[0] + ny * t * up[0],
                fwd[1] + nx * t * cam.aspect * right[1] + ny * t * up[1],
                fwd[2] + nx * t * cam.aspect * right[2] + ny * t * up[2]);
}

// Made on first use, kept for the whole test program.
inline ViewerGl& viewer_gl() {
    static ViewerGl gl = [] {
        ViewerGl g;
        try {
            g.context = std::make_unique<viewer::HeadlessContext>();
            g.programs = std::make_unique<viewer::GpuPrograms>();
        } catch (const Error& e) {
            g.programs.reset();
            g.error = e.what();
        }
        return g;
    }();
    return gl;
}

#define FIBLET_REQUIRE_GL()                                                                        \
    do {                                                                                           \
        if (!::fiblet::test::viewer_gl().programs)                                                 \
            GTEST_SKIP() << "no headless OpenGL 4.5 context: " << ::fiblet::test::viewer_gl().error; \
    } while (0)

// Compresses `tck` into `dir` with 8-bit directions (what the viewer's GPU
// decoders read) and returns the .fft path.
inline std::string compress_into(const TempDir& dir, const std::string& tck, const std::string& name) {
    const std::string out = dir.file(name);
    CompressOptions o;
    o.direction_bits = 8;  // the default chooses 16 for smooth fibers (encode/direction_bits.hpp)
    o.threads = 1;
    o.overwrite = true;
    compress_file(tck, out, o);
    return out;
}

// Writes `fibers` as a .tck file.
inline void write_tck(const std::string& path, const std::vector<std::vector<Vec3f>>& fibers) {
    TckWriter w(path, {}, true);
    for (const auto& f : fibers) w.write(f);
    w.finish();
}

// Writes `fibers` as NAME.tck in `dir`, compresses it and returns the .fft path.
inline std::string compress_fibers(const TempDir& dir, const std::vector<std::vector<Vec3f>>& fibers,
                                   const std::string& name) {
    write_tck(dir.file(name + ".tck"), fibers);
    return compress_into(dir, dir.file(name + ".tck"), name + ".fft");
}

// Compresses `tck` into `dir` with 16-bit direction codes (formats/fft16.md):
// version 17 in a .fft, or version 16 in a .fftz with `zstd`.
// `points_per_block` 0: the encoder's default (254, 126 in a .fftz).
inline std::string compress16_into(const TempDir& dir, const std::string& tck, const std::string& name, bool zstd,
                                   std::uint32_t points_per_block = 0) {
    const std::string out = dir.file(name);
    CompressOptions o;
    o.threads = 1;
    o.overwrite = true;
    o.direction_bits = 16;
    o.points_per_block = points_per_block;
    if (zstd) o.zstd = ZstdOptions{};
    compress_file(tck, out, o);
    return out;
}

// Fibers (or a .tck file) compressed into a temporary file and uploaded: what most viewer tests draw.
struct CompressedScene {
    TempDir dir;
    FftFile file;
    viewer::GpuScene scene;
    explicit CompressedScene(const std::vector<std::vector<Vec3f>>& fibers)
        : file(compress_fibers(dir, fibers, "scene")), scene(file, *viewer_gl().programs) {}
    explicit CompressedScene(const std::string& tck)
        : file(compress_into(dir, tck, "scene.fft")), scene(file, *viewer_gl().programs) {}
};

// Every block of a file decoded by the scalar reference decoder (with the
// file's last-step fractions, as every decoder of a file applies them): xyz of each
// block's points one after the other, and the offset of each block's first point.
struct CpuDecoded {
    std::vector<float> xyz;
    std::vector<std::size_t> block_first;  // blocks + 1 entries
    Vec3f point(std::size_t i) const { return {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]}; }
};
inline CpuDecoded cpu_decode_blocks(const FftFile& f) {
    const DecodeContext ctx(f);
    const auto blocks = f.read_blocks(0, f.header().blocks);
    CpuDecoded d;
    d.xyz.resize(3 * count_block_points(ctx, blocks.data(), f.header().blocks));
    decode_blocks(ctx, blocks.data(), f.header().blocks, d.xyz.data(), {DecoderKind::scalar});
    const std::uint32_t bb = f.header().block_bytes();
    d.block_first.push_back(0);
    for (std::uint32_t b = 0; b < f.header().blocks; ++b)
        d.block_first.push_back(d.block_first.back() + block_flags(f.header(), &blocks[std::size_t(b) * bb]).point_count);
    return d;
}

// A point projected with a view-projection matrix: window coordinates with
// the origin at the top-left of the image, and clip w.
struct Projected {
    float x, y, w;
};
inline std::array<float, 4> clip_of(const Mat4& m, Vec3f p) {
    std::array<float, 4> c{};
    for (int r = 0; r < 4; ++r) c[r] = m[r] * p.x + m[4 + r] * p.y + m[8 + r] * p.z + m[12 + r];
    return c;
}
inline Projected to_window(const std::array<float, 4>& c, int width, int height) {
    return {(c[0] / c[3] * 0.5f + 0.5f) * float(width), (0.5f - c[1] / c[3] * 0.5f) * float(height), c[3]};
}

// Reference rasterization of a segment, after clipping to the near plane: one
// pixel per pixel centre crossed along the major axis, from the first end
// (included) to the second (excluded): how GL's aliased one-pixel lines
// cover up to the diamond-exit rule's choices at the ends. Calls pixel(x, y)
// for the pixels inside the image.
// With `touched`, every pixel the segment touches instead, both ends
// included (a superset: which segments may have coloured a pixel).
template <class Pixel>
void rasterize_segment(const Mat4& view_projection, Vec3f p0, Vec3f p1, int width, int height, Pixel&& pixel,
                       bool touched = false) {
    auto c0 = clip_of(view_projection, p0), c1 = clip_of(view_projection, p1);
    const float d0 = c0[2] + c0[3], d1 = c1[2] + c1[3];  // >= 0 in front of the near plane
    if (d0 < 0 && d1 < 0) return;
    auto lerp = [](const std::array<float, 4>& a, const std::array<float, 4>& b, float t) {
        std::array<float, 4> r{};
        for (int i = 0; i < 4; ++i) r[i] = a[i] + t * (b[i] - a[i]);
        return r;
    };
    if (d0 < 0) c0 = lerp(c0, c1, d0 / (d0 - d1));
    if (d1 < 0) c1 = lerp(c0, c1, d0 / (d0 - d1));
    const Projected a = to_window(c0, width, height), b = to_window(c1, width, height);
    if (touched) {
        const int n = std::max(1, int(std::ceil(2 * std::max(std::fabs(b.x - a.x), std::fabs(b.y - a.y)))));
        for (int i = 0; i <= n; ++i) {
            const float t = float(i) / float(n);
            const int x = int(std::floor(a.x + t * (b.x - a.x))), y = int(std::floor(a.y + t * (b.y - a.y)));
            if (x >= 0 && y >= 0 && x < width && y < height) pixel(x, y);
        }
        return;
    }
    const bool x_major = std::fabs(b.x - a.x) >= std::fabs(b.y - a.y);
    // Coordinates along the major (u) and minor (v) axes.
    const float u0 = x_major ? a.x : a.y, u1 = x_major ? b.x : b.y;
    const float v0 = x_major ? a.y : a.x, v1 = x_major ? b.y : b.x;
    if (u0 == u1) return;
    const float dir = u1 > u0 ? 1.0f : -1.0f;
    // Pixel centres c + 0.5 between u0 (included) and u1 (excluded).
    for (float c = dir > 0 ? std::ceil(u0 - 0.5f) + 0.5f : std::floor(u0 - 0.5f) + 0.5f; dir * (u1 - c) > 0; c += dir) {
        if (dir * (c - u0) < 0) continue;
        const float v = v0 + (c - u0) / (u1 - u0) * (v1 - v0);
        const int pu = int(std::floor(c)), pv = int(std::floor(v));
        const int x = x_major ? pu : pv, y = x_major ? pv : pu;
        if (x >= 0 && y >= 0 && x < width && y < height) pixel(x, y);
    }
}

}  // namespace fiblet::test
