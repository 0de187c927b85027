// Headless rendering against a CPU reference rasterization of the same
// decoded segments under the same camera (metric: docs/viewer.md, "Tests").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scene/gpu_scene.hpp"
#include "window/orbit_camera.hpp"
#include "gl/png_file.hpp"
#include "render/render_target.hpp"
#include "render/renderer.hpp"
#include "viewer_test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;

namespace {

struct Segment {
    Vec3f a, b;
    std::uint32_t fiber;
};

// What the reference rasterizer wrote at one pixel: whether a segment
// covers it, and the fiber and colour (|direction| as RGB, 0..255) of every
// segment that touches it, whatever their depth.
struct ReferencePixel {
    bool covered = false;
    std::vector<std::pair<std::uint32_t, std::array<int, 3>>> hits;
};

std::vector<ReferencePixel> rasterize(const std::vector<Segment>& segments, const Camera& cam, int w, int h) {
    std::vector<ReferencePixel> image(std::size_t(w) * std::size_t(h));
    const Mat4 vp = view_projection_matrix(cam);
    for (const Segment& s : segments) {
        const double dx = s.b.x - s.a.x, dy = s.b.y - s.a.y, dz = s.b.z - s.a.z;
        const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
        const std::array<int, 3> color =
            len > 0 ? std::array<int, 3>{int(std::lround(std::fabs(dx) / len * 255)), int(std::lround(std::fabs(dy) / len * 255)),
                                         int(std::lround(std::fabs(dz) / len * 255))}
                    : std::array<int, 3>{0, 0, 0};
        rasterize_segment(vp, s.a, s.b, w, h,
                          [&](int x, int y) { image[std::size_t(y) * std::size_t(w) + std::size_t(x)].covered = true; });
        rasterize_segment(
            vp, s.a, s.b, w, h,
            [&](int x, int y) { image[std::size_t(y) * std::size_t(w) + std::size_t(x)].hits.emplace_back(s.fiber, color); },
            true);
    }
    return image;
}

// Coverage agreement after a one-pixel dilation, and the share of GPU pixels
// whose fiber and colour are those of a reference segment within one pixel.
struct Agreement {
    std::size_t gpu_pixels = 0, cpu_pixels = 0;
    double gpu_covered_by_cpu = 0, cpu_covered_by_gpu = 0, fiber_matches = 0, color_matches = 0;
};

Agreement compare(const std::vector<std::uint32_t>& fibers, const std::vector<std::uint8_t>& rgba,
                  const std::vector<ReferencePixel>& ref, int w, int h) {
    auto at = [&](int x, int y) { return std::size_t(y) * std::size_t(w) + std::size_t(x); };
    auto near = [&](int x, int y, auto&& pred) {
        for (int yy = std::max(y - 1, 0); yy <= std::min(y + 1, h - 1); ++yy)
            for (int xx = std::max(x - 1, 0); xx <= std::min(x + 1, w - 1); ++xx)
                if (pred(at(xx, yy))) return true;
        return false;
    };
    Agreement a;
    std::size_t g_in_c = 0, c_in_g = 0, fiber_ok = 0, color_ok = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = at(x, y);
            if (fibers[i] != 0) {
                ++a.gpu_pixels;
                g_in_c += near(x, y, [&](std::size_t j) { return ref[j].covered; });
                fiber_ok += near(x, y, [&](std::size_t j) {
                    for (const auto& hit : ref[j].hits)
                        if (hit.first + 1 == fibers[i]) return true;
                    return false;
                });
                color_ok += near(x, y, [&](std::size_t j) {
                    for (const auto& hit : ref[j].hits) {
                        bool same = true;
                        for (int c = 0; c < 3; ++c) same &= std::abs(int(rgba[4 * i + std::size_t(c)]) - hit.second[std::size_t(c)]) <= 3;
                        if (same) return true;
                    }
                    return false;
                });
            }
            if (ref[i].covered) {
                ++a.cpu_pixels;
                c_in_g += near(x, y, [&](std::size_t j) { return fibers[j] != 0; });
            }
        }
    a.gpu_covered_by_cpu = a.gpu_pixels ? double(g_in_c) / double(a.gpu_pixels) : 0;
    a.cpu_covered_by_gpu = a.cpu_pixels ? double(c_in_g) / double(a.cpu_pixels) : 0;
    a.fiber_matches = a.gpu_pixels ? double(fiber_ok) / double(a.gpu_pixels) : 0;
    a.color_matches = a.gpu_pixels ? double(color_ok) / double(a.gpu_pixels) : 0;
    return a;
}

void expect_agreement(const Agreement& a, std::size_t min_pixels) {
    EXPECT_GT(a.gpu_pixels, min_pixels);
    // As many pixels (the dilated comparisons alone would let a dense
    // bundle hide missing or extra lines).
    EXPECT_NEAR(double(a.gpu_pixels) / double(std::max<std::size_t>(a.cpu_pixels, 1)), 1.0, 0.02);
    EXPECT_GE(a.gpu_covered_by_cpu, 0.99);
    EXPECT_GE(a.cpu_covered_by_gpu, 0.99);
    EXPECT_GE(a.fiber_matches, 0.99);
    EXPECT_GE(a.color_matches, 0.99);
    std::printf("%zu GPU / %zu reference pixels; coverage %.4f / %.4f, fiber %.4f, colour %.4f\n", a.gpu_pixels,
                a.cpu_pixels, a.gpu_covered_by_cpu, a.cpu_covered_by_gpu, a.fiber_matches, a.color_matches);
}

// Every segment of every fiber, decoded on the CPU.
std::vector<Segment> all_segments(const FftFile& file) {
    const Streamlines s = decode_fibers(file, 0, file.header().fibers);
    std::vector<Segment> out;
    for (std::size_t f = 0; f < s.size(); ++f)
        for (std::uint64_t i = s.offsets[f]; i + 1 < s.offsets[f + 1]; ++i)
            out.push_back({{s.xyz[3 * i], s.xyz[3 * i + 1], s.xyz[3 * i + 2]},
                           {s.xyz[3 * i + 3], s.xyz[3 * i + 4], s.xyz[3 * i + 5]},
                           std::uint32_t(f)});
    return out;
}

// The segments the level of detail draws, decided on the CPU by view.hpp: a
// coarse block is one segment from its first point to the next block's
// first point (or its fiber's last point), other blocks are drawn in full.
std::vector<Segment> lod_segments(const FftFile& file, const Camera& cam, const Viewport& vp, float lod_pixels,
                                  std::size_t& coarse) {
    const CpuDecoded d = cpu_decode_blocks(file);
    const auto blocks = file.read_blocks(0, file.header().blocks);
    const std::uint32_t bb = file.header().block_bytes();
    std::vector<Segment> out;
    coarse = 0;
    for (std::uint64_t f = 0; f < file.header().fibers; ++f) {
        const std::uint64_t first = file.first_block(f), end = first + file.block_count(f);
        for (std::uint64_t b = first; b < end; ++b) {
            const Sphere s = block_bounding_sphere(file.header(), &blocks[b * bb]);
            const std::size_t p0 = d.block_first[b];
            const std::size_t p_end = b + 1 < end ? d.block_first[b + 1] + 1 : d.block_first[b + 1];
            if (block_is_coarse(cam, vp, s.center, s.radius, lod_pixels)) {
                ++coarse;
                if (p_end - p0 >= 2) out.push_back({d.point(p0), d.point(p_end - 1), std::uint32_t(f)});
            } else {
                for (std::size_t i = p0; i + 1 < p_end; ++i) out.push_back({d.point(i), d.point(i + 1), std::uint32_t(f)});
            }
        }
    }
    return out;
}

viewer::RenderOptions flat_direction_colors() {
    viewer::RenderOptions o;
    o.lighting = false;  // colours are then exactly |direction|
    o.color_by_direction = true;
    return o;
}

}  // namespace

TEST(ViewerRender, MatchesAReferenceRasterizationOfTheDecodedSegments) {
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(shared_data("bundles/CST_R-step0.1.tck"));
    const FftFile& file = compressed.file;
    const viewer::GpuScene& scene = compressed.scene;
    viewer::Renderer renderer(*viewer_gl().programs);
    const int w = 160, h = 120;
    viewer::RenderTarget target(w, h);
    for (const char* view : {"oblique", "front", "top"}) {
        SCOPED_TRACE(view);
        const Camera cam = viewer::camera_from_spec(view, scene, float(w) / float(h), 35, 1);
        viewer::RenderOptions o = flat_direction_colors();
        o.level_of_detail = false;
        const viewer::FrameStats stats = renderer.render(scene, cam, o, target);
        EXPECT_EQ(stats.fine_segments, file.header().points - file.header().fibers);
        const auto ref = rasterize(all_segments(file), cam, w, h);
        expect_agreement(compare(target.read_fibers(), target.read_rgba(), ref, w, h), 500);
    }
}

namespace {
// The level of detail of `file` against view.hpp's decisions on the CPU.
void expect_lod_matches_reference(const FftFile& file, const viewer::GpuScene& scene, float lod_pixels) {
    viewer::Renderer renderer(*viewer_gl().programs);
    const int w = 256, h = 192;
    viewer::RenderTarget target(w, h);
    // A level-of-detail threshold of 16 pixels (60-point blocks) makes most
    // blocks coarse in an image large enough to compare.
    const Camera cam = viewer::camera_from_spec("oblique", scene, float(w) / float(h), 35, 0.5f);
    viewer::RenderOptions o = flat_direction_colors();
    o.lod_pixels = lod_pixels;
    const viewer::FrameStats stats = renderer.render(scene, cam, o, target);
    std::size_t coarse = 0;
    const auto ref = rasterize(lod_segments(file, cam, {w, h}, o.lod_pixels, coarse), cam, w, h);
    EXPECT_GT(stats.coarse_blocks, scene.block_count() / 2);
    EXPECT_NEAR(double(stats.coarse_blocks), double(coarse), 2.0);
    expect_agreement(compare(target.read_fibers(), target.read_rgba(), ref, w, h), 400);
}
}  // namespace

TEST(ViewerRender, LevelOfDetailMatchesTheReferenceOfCoarseBlocks) {
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(shared_data("bundles/cingulum-2-step0.1.tck"));
    expect_lod_matches_reference(compressed.file, compressed.scene, 16);
}

// 16-bit blocks (254 points, unorm24 anchors): the culling pass's spheres,
// coarse chords and fiber ends read the wide layout.
TEST(ViewerRender, LevelOfDetailOfSixteenBitFiles) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const FftFile file(compress16_into(dir, shared_data("bundles/cingulum-2-step0.1.tck"), "c16.fft", false));
    const viewer::GpuScene scene(file, *viewer_gl().programs);
    expect_lod_matches_reference(file, scene, 64);  // blocks four times as long
}

TEST(ViewerRender, MatchesAReferenceRasterizationOfSixteenBitFiles) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const FftFile file(compress16_into(dir, shared_data("bundles/CST_R-step0.1.tck"), "cst16.fft", false));
    const viewer::GpuScene scene(file, *viewer_gl().programs);
    viewer::Renderer renderer(*viewer_gl().programs);
    const int w = 160, h = 120;
    viewer::RenderTarget target(w, h);
    const Camera cam = viewer::camera_from_spec("oblique", scene, float(w) / float(h), 35, 1);
    viewer::RenderOptions o = flat_direction_colors();
    o.level_of_detail = false;
    EXPECT_EQ(renderer.render(scene, cam, o, target).fine_segments, file.header().points - file.header().fibers);
    expect_agreement(compare(target.read_fibers(), target.read_rgba(), rasterize(all_segments(file), cam, w, h), w, h),
                     500);
}

TEST(ViewerRender, PngRoundTrip) {
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(shared_data("bundles/AF_L.tck"));
    const viewer::GpuScene& scene = compressed.scene;
    viewer::Renderer renderer(*viewer_gl().programs);
    viewer::RenderTarget target(97, 61);  // odd sizes: no row padding assumptions
    const Camera cam = viewer::camera_from_spec("left", scene, 97.0f / 61.0f, 35, 1);
    renderer.render(scene, cam, {}, target);
    const viewer::RgbaImage image{97, 61, target.read_rgba()};
    viewer::write_png(compressed.dir.file("a.png"), image, false);
    const viewer::RgbaImage back = viewer::read_png(compressed.dir.file("a.png"));
    ASSERT_EQ(back.width, 97);
    ASSERT_EQ(back.height, 61);
    EXPECT_EQ(back.rgba, image.rgba);  // opaque renders: alpha is 255 both sides
    EXPECT_THROW(viewer::write_png(compressed.dir.file("a.png"), image, false), Error);  // exists
}
