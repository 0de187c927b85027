// 16-bit files (formats/fft16.md) through every way the viewer draws: the
// same fibers compressed with 8-bit and with 16-bit codes, rendered under one
// camera, give the same image up to the pixels that the two codecs' small
// differences of position (a few µm against pixels of a fifth of a mm) move
// across a pixel's sampling point.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "scene/gpu_scene.hpp"
#include "window/orbit_camera.hpp"
#include "render/render_target.hpp"
#include "render/renderer.hpp"
#include "techniques/tubes/tubes_technique.hpp"
#include "viewer_test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;

namespace {

struct Image {
    std::vector<std::uint8_t> rgba;
    std::vector<std::uint32_t> fibers;  // fiber index + 1 (0: background), opaque frames only
};

Image render(const viewer::GpuScene& scene, const Camera& cam, const viewer::RenderOptions& o, int w, int h) {
    viewer::Renderer renderer(*viewer_gl().programs);
    viewer::RenderTarget target(w, h);
    renderer.render(scene, cam, o, target);
    return {target.read_rgba(), target.read_fibers()};
}

// Pixels drawn (not the background) in either image, the share of them drawn
// in both, and among those the share whose colours differ by more than 8 of
// 255 in some channel, and (opaque frames) the share showing another fiber.
struct ImageAgreement {
    std::size_t drawn = 0;
    double both = 0, color_differs = 0, fiber_differs = 0;
};

ImageAgreement compare(const Image& a, const Image& b, bool compare_fibers) {
    ImageAgreement r;
    std::size_t both = 0, color = 0, fiber = 0;
    for (std::size_t i = 0; i < a.rgba.size() / 4; ++i) {
        auto drawn = [&](const Image& m) {
            return m.rgba[4 * i] != 0 || m.rgba[4 * i + 1] != 0 || m.rgba[4 * i + 2] != 0;
        };
        const bool da = drawn(a), db = drawn(b);
        if (!da && !db) continue;
        ++r.drawn;
        if (!da || !db) continue;
        ++both;
        int d = 0;
        for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(a.rgba[4 * i + c]) - int(b.rgba[4 * i + c])));
        color += d > 8;
        fiber += compare_fibers && a.fibers[i] != b.fibers[i];
    }
    r.both = r.drawn ? double(both) / double(r.drawn) : 0;
    r.color_differs = both ? double(color) / double(both) : 0;
    r.fiber_differs = both ? double(fiber) / double(both) : 0;
    return r;
}

struct Case {
    const char* name;
    viewer::RenderOptions options;
    bool opaque;
    // Sorted transparency of ray-cast styles blends overlapping ~1 mm chunks
    // in depth order, and chunks start at block starts: blocks of another
    // length (254 points against 60) make other chunks, another order where
    // tubes overlap, and another image (8-bit files of 61 or 63 points a
    // block differ from 60 as much: 60 % of the pixels for tubes). These
    // compare with a 16-bit file of 60-point blocks, whose chunks are the
    // 8-bit file's.
    bool chunk_order = false;
    // Share of the pixels drawn in both whose colour may differ: voxlines
    // order 10 mm voxels by the fibers' points, so a few µm move some
    // blends across a voxel face (measured 3.6 %); elsewhere measured <= 0.75 %.
    double color_differs = 0.02;
};

std::vector<Case> every_technique() {
    viewer::RenderOptions base;
    base.level_of_detail = false;  // coarse chords span a block: 60 points at 8 bits, 254 at 16
    std::vector<Case> cases;
    auto add = [&](const char* name, auto&& set, bool opaque, bool chunk_order = false) {
        viewer::RenderOptions o = base;
        set(o);
        cases.push_back({name, o, opaque, chunk_order});
        return &cases.back();
    };
    add("lines", [](viewer::RenderOptions&) {}, true);
    add("lines, scan decoder", [](viewer::RenderOptions& o) { o.decoder = viewer::GpuDecoder::scan; }, true);
    add("tubes", [](viewer::RenderOptions& o) { o.style = viewer::DrawStyle::tubes; }, true);
    add("capsules", [](viewer::RenderOptions& o) { o.style = viewer::DrawStyle::capsules; }, true);
    add("lines, sorted transparency", [](viewer::RenderOptions& o) { o.opacity = 0.4f; }, false);
    add("tubes, sorted transparency", [](viewer::RenderOptions& o) {
        o.style = viewer::DrawStyle::tubes;
        o.opacity = 0.4f;
    }, false, true);
    add("capsules, sorted transparency", [](viewer::RenderOptions& o) {
        o.style = viewer::DrawStyle::capsules;
        o.opacity = 0.4f;
    }, false, true);
    add("lines, voxlines", [](viewer::RenderOptions& o) {
        o.opacity = 0.4f;
        o.transparency = viewer::TransparencyMode::voxlines;
    }, false)->color_differs = 0.06;
    add("voxel-rt", [](viewer::RenderOptions& o) {
        o.engine = viewer::RenderEngine::voxel_rt;
        o.voxel_grid = 64;
    }, true);
    return cases;
}

}  // namespace

TEST(ViewerSixteenBit, EveryTechniqueDrawsTheImageOfTheEightBitFile) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string tck = shared_data("bundles/CST_R-step0.1.tck");
    const FftFile f8(compress_into(dir, tck, "cst8.fft"));
    const viewer::GpuScene scene8(f8, *viewer_gl().programs);
    const int w = 160, h = 120;
    for (const bool zstd : {false, true}) {
        const FftFile f16(compress16_into(dir, tck, zstd ? "cst16.fftz" : "cst16.fft", zstd));
        const FftFile f16_60(compress16_into(dir, tck, zstd ? "cst16-60.fftz" : "cst16-60.fft", zstd, 60));
        const viewer::GpuScene scene16(f16, *viewer_gl().programs), scene16_60(f16_60, *viewer_gl().programs);
        ASSERT_EQ(scene16.fiber_count(), scene8.fiber_count());
        for (const char* view : {"oblique", "left"}) {
            const Camera cam = viewer::camera_from_spec(view, scene8, float(w) / float(h), 35, 1.5f);
            for (const Case& c : every_technique()) {
                const viewer::GpuScene& wide = c.chunk_order ? scene16_60 : scene16;
                SCOPED_TRACE(std::string(c.name) + ", " + view + (zstd ? ", version 16" : ", version 17"));
                const ImageAgreement a =
                    compare(render(scene8, cam, c.options, w, h), render(wide, cam, c.options, w, h), c.opaque);
                std::printf("%-30s %-7s v%d, %3u points a block: %zu pixels drawn, %.2f %% in both, colour differs "
                            "(> 8/255) at %.2f %%, fiber at %.2f %%\n",
                            c.name, view, int(f16.header().version), wide.header().points_per_block, a.drawn,
                            100 * a.both, 100 * a.color_differs, 100 * a.fiber_differs);
                // The codecs place points within a few µm of the input (8-bit:
                // 5 µm), pixels here are a few tenths of a mm: a segment changes pixels only
                // where it passes within ~1 % of a pixel of a sampling point.
                // Measured (both files, both views): drawn in both >= 99.88 %,
                // colour differs <= 0.75 % (voxlines 3.6 %), fiber <= 0.1 %.
                EXPECT_GT(a.drawn, std::size_t(w * h / 20));
                EXPECT_GE(a.both, 0.99);
                EXPECT_LE(a.color_differs, c.color_differs);
                EXPECT_LE(a.fiber_differs, 0.01);
            }
        }
    }
}

// What the culling and the selection see: a frame of a 16-bit file draws
// every segment (no level of detail), and the fiber subset keeps the same
// fibers as the 8-bit file's.
TEST(ViewerSixteenBit, CullingAndSelectionCountTheSameSegments) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string tck = shared_data("bundles/CST_R-step0.1.tck");
    const FftFile f16(compress16_into(dir, tck, "cst16.fft", false));
    const viewer::GpuScene scene16(f16, *viewer_gl().programs);
    viewer::Renderer renderer(*viewer_gl().programs);
    viewer::RenderTarget target(96, 64);
    const Camera cam = viewer::camera_from_spec("oblique", scene16, 1.5f, 35, 1);
    viewer::RenderOptions o;
    o.level_of_detail = false;
    EXPECT_EQ(renderer.render(scene16, cam, o, target).fine_segments, f16.header().points - f16.header().fibers);
    // Fibers by the ID stored in their blocks (cull_blocks.comp.glsl reads it).
    o.id_min = 10, o.id_max = 29;
    std::uint64_t want = 0;
    for (std::uint64_t f = 0; f < scene16.fiber_count(); ++f)
        if (scene16.fiber_id(f) >= 10 && scene16.fiber_id(f) <= 29) want += scene16.fiber_points(f) - 1;
    EXPECT_GT(want, 0u);
    EXPECT_EQ(renderer.render(scene16, cam, o, target).fine_segments, want);
}

// Tube pieces of a batch that would exceed the largest storage buffer (a
// full batch of 254-point blocks: 190 MB) are built and drawn in runs of
// slots: runs of a few slots draw the image of one run.
TEST(ViewerSixteenBit, TubePiecesInRunsDrawTheSameImage) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const FftFile f16(compress16_into(dir, shared_data("bundles/CST_R-step0.1.tck"), "cst16.fft", false));
    const viewer::GpuScene scene(f16, *viewer_gl().programs);
    const int w = 160, h = 120;
    const Camera cam = viewer::camera_from_spec("oblique", scene, float(w) / float(h), 35, 1.5f);
    for (const float opacity : {1.0f, 0.4f}) {
        SCOPED_TRACE(opacity);
        viewer::RenderOptions o;
        o.level_of_detail = false;
        o.style = viewer::DrawStyle::tubes;
        o.opacity = opacity;
        std::vector<Image> images;
        for (const bool runs : {false, true}) {
            auto tubes = std::make_unique<viewer::TubesTechnique>();
            // Pieces of 3 segments (2 x 112 B each): runs of one slot (a
            // block: ceil(254 / s) segments) or, sorted, of a few chunks.
            if (runs) tubes->set_piece_buffer_limit(3 * 2 * 112);
            viewer::Renderer renderer(*viewer_gl().programs);
            renderer.use_technique(viewer::DrawStyle::tubes, std::move(tubes));
            viewer::RenderTarget target(w, h);
            renderer.render(scene, cam, o, target);
            images.push_back({target.read_rgba(), target.read_fibers()});
        }
        EXPECT_EQ(images[0].rgba, images[1].rgba);
        if (opacity == 1.0f) {
            EXPECT_EQ(images[0].fibers, images[1].fibers);
        }
        EXPECT_GT(std::count_if(images[0].fibers.begin(), images[0].fibers.end(), [](std::uint32_t f) { return f != 0; }) +
                      std::count_if(images[0].rgba.begin(), images[0].rgba.end(), [](std::uint8_t c) { return c != 0; }),
                  1000);
    }
}
