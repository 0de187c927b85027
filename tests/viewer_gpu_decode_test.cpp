// The two GPU decoders (decode_blocks*.comp.glsl, run headless on whatever EGL
// offers: llvmpipe in CI) against the scalar reference decoder, on every
// shared test file and on fibers whose lengths hit every block boundary case.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scene/block_decoder.hpp"
#include "scene/gpu_scene.hpp"
#include "viewer_test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;

namespace {

constexpr viewer::GpuDecoder kBothDecoders[] = {viewer::GpuDecoder::scan, viewer::GpuDecoder::sequential};

// Largest coordinate difference between the two decoders, in mm. Both
// decode the same bytes; the GPU multiplies the frames in a different order
// (a log-step scan instead of one after the other), so they differ by float
// rounding only.
struct Comparison {
    std::size_t points = 0;
    double max_diff_mm = 0;
};

Comparison compare_decoders(const std::string& fft_path, viewer::GpuDecoder kind) {
    const FftFile file(fft_path);
    const viewer::GpuScene scene(file, *viewer_gl().programs, kind);
    const std::vector<float> gpu =
        viewer::decode_blocks_on_gpu(scene, *viewer_gl().programs, kind, 0, scene.block_count());
    const CpuDecoded cpu = cpu_decode_blocks(file);
    EXPECT_EQ(gpu.size(), cpu.xyz.size()) << fft_path;
    Comparison c;
    c.points = std::min(gpu.size(), cpu.xyz.size()) / 3;
    for (std::size_t i = 0; i < 3 * c.points; ++i)
        c.max_diff_mm = std::max(c.max_diff_mm, double(std::fabs(gpu[i] - cpu.xyz[i])));

    // The last point of each fiber, decoded on the GPU at load for the level of detail.
    const std::vector<Vec3f> ends = scene.read_fiber_ends();
    for (std::uint64_t f = 0; f < file.header().fibers; ++f) {
        if (file.block_count(f) == 0) continue;
        const std::uint64_t last_block = file.first_block(f) + file.block_count(f) - 1;
        const Vec3f want = cpu.point(cpu.block_first[last_block + 1] - 1);
        c.max_diff_mm = std::max({c.max_diff_mm, double(std::fabs(ends[f].x - want.x)),
                                  double(std::fabs(ends[f].y - want.y)), double(std::fabs(ends[f].z - want.z))});
    }
    return c;
}

// Float rounding bound: 2e-6 normalized units (about 30 units in the last
// place of a coordinate near 0.5, accumulated over a block's 60 steps), i.e.
// 0.17 µm for a 87 mm wide tractogram: a hundred times under the 8-bit
// codec's own error. Measured: 4.8e-5 mm on the reference files (0.55e-6
// units). 16-bit files keep it up to 254 points a block (version 17's
// default; measured on AF_L, scaling 80 mm: 7.6e-5 mm scan, 1.1e-5 mm
// sequential, under half the bound and a seventh of the 16-bit codec's 0.5
// µm); longer blocks walk further from their anchors, and the rounding of a
// walk of n steps grows like sqrt(n) (measured at 1000 points: 1.5e-4 mm),
// so the bound grows as sqrt(points per block / 254) beyond.
double tolerance_mm(const std::string& fft_path) {
    const FftHeader h = FftFile(fft_path).header();
    return 2e-6 * std::max(1.0, std::sqrt(h.points_per_block / 254.0)) * h.scaling;
}

// Both GPU decoders against the scalar decoder on `fft` (named `name`), which
// decodes to more than `more_points_than` points.
void expect_gpu_decoders_match_scalar(const std::string& fft, const char* name, std::size_t more_points_than) {
    for (const auto kind : kBothDecoders) {
        const Comparison c = compare_decoders(fft, kind);
        EXPECT_GT(c.points, more_points_than) << name;
        EXPECT_LE(c.max_diff_mm, tolerance_mm(fft)) << name << " " << viewer::gpu_decoder_name(kind);
        std::printf("%s: %zu points, GPU (%s) vs scalar decoder max %.3g mm\n", name, c.points,
                    viewer::gpu_decoder_name(kind), c.max_diff_mm);
    }
}

// The unit tangents the decoders emit for the tubes: the direction of the
// step arriving at each point (F0), the first point taking its first step's.
void expect_tangents_are_unit_step_directions(const FftFile& file, const viewer::GpuScene& scene) {
    const CpuDecoded cpu = cpu_decode_blocks(file);
    for (const auto kind : {viewer::GpuDecoder::sequential, viewer::GpuDecoder::scan}) {
        SCOPED_TRACE(viewer::gpu_decoder_name(kind));
        const auto t = viewer::decode_tangents_on_gpu(scene, *viewer_gl().programs, kind, 0, scene.block_count());
        ASSERT_EQ(t.size(), cpu.xyz.size());
        double worst = 0;
        std::size_t checked = 0;
        for (std::uint32_t b = 0; b < scene.block_count(); ++b) {
            const std::size_t first = cpu.block_first[b], n = cpu.block_first[b + 1] - first;
            if (n < 2) continue;
            for (std::size_t k = 0; k < n; ++k) {
                // Point 0 takes the first step's direction, point k the step arriving at it.
                const std::size_t i = first + std::max<std::size_t>(k, 1);
                const Vec3f p0 = cpu.point(i - 1), p1 = cpu.point(i);
                const double dx = double(p1.x) - p0.x, dy = double(p1.y) - p0.y, dz = double(p1.z) - p0.z;
                const double length = std::sqrt(dx * dx + dy * dy + dz * dz);
                const double ex = t[3 * (first + k)] - dx / length, ey = t[3 * (first + k) + 1] - dy / length,
                             ez = t[3 * (first + k) + 2] - dz / length;
                // The CPU direction is a difference of float points (about
                // 1e-5 mm rounding near 100 mm), over a step of 0.1 mm or,
                // for a fiber's shortened last step (ENDS), much less.
                worst = std::max(worst, std::sqrt(ex * ex + ey * ey + ez * ez) / (1e-4 + 2e-5 / length));
                ++checked;
            }
        }
        EXPECT_GT(checked, 10000u);
        EXPECT_LE(worst, 1.0);  // error / tolerance
        std::printf("%s tangents: %zu points, worst error / tolerance %.3g\n", viewer::gpu_decoder_name(kind), checked, worst);
    }
}

}  // namespace

TEST(ViewerGpuDecode, ReferenceFilesWrittenByTheOfficialEncoder) {
    FIBLET_REQUIRE_GL();
    for (const char* name : {"reference/small-ifod1.fft", "reference/small-sdstream.fft"}) {
        expect_gpu_decoders_match_scalar(shared_data(name), name, 100000);
    }
}

TEST(ViewerGpuDecode, SharedTractogramsCompressedHere) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    for (const char* name :
         {"bundles/AF_L-step0.1.tck", "bundles/CC_ForcepsMajor-step0.1.tck", "bundles/CST_R-step0.1.tck",
          "bundles/cingulum-1-step0.1.tck", "bundles/cingulum-2-step0.1.tck", "bundles/AF_L.tck",
          "dwi-small64d-ifod1.tck", "conformance/simple.tck", "conformance/standard.tck"}) {
        expect_gpu_decoders_match_scalar(compress_into(dir, shared_data(name), "f.fft"), name, 0);
    }
}

TEST(ViewerGpuDecode, EveryBlockBoundaryCase) {
    FIBLET_REQUIRE_GL();
    // Helices of 1..3, 59..62, 119..121 points: one-point fibers and blocks,
    // two-point blocks, full blocks, and a sharp turn (cap ratio near 2).
    std::vector<std::vector<Vec3f>> fibers;
    for (int n : {1, 2, 3, 59, 60, 61, 62, 119, 120, 121}) {
        std::vector<Vec3f> f;
        for (int i = 0; i < n; ++i) {
            const float t = 0.05f * float(i) + 0.3f * float(n);
            f.push_back({10 * std::cos(t) + float(n), 10 * std::sin(t), 0.5f * float(i)});
        }
        fibers.push_back(f);
    }
    fibers.push_back({{0, 0, 0}, {0.5f, 0, 0}, {0.5f, 0.5f, 0}, {0, 0.5f, 0}, {0, 0.5f, 0.5f}});
    const TempDir dir;
    write_tck(dir.file("cases.tck"), fibers);
    const std::string fft = compress_into(dir, dir.file("cases.tck"), "cases.fft");
    for (const auto kind : kBothDecoders) {
        const Comparison c = compare_decoders(fft, kind);
        EXPECT_EQ(c.points, FftFile(fft).header().points) << viewer::gpu_decoder_name(kind);
        EXPECT_LE(c.max_diff_mm, tolerance_mm(fft)) << viewer::gpu_decoder_name(kind);
    }
}


TEST(ViewerGpuDecode, TangentsAreTheUnitStepDirections) {
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(shared_data("bundles/AF_L-step0.1.tck"));
    expect_tangents_are_unit_step_directions(compressed.file, compressed.scene);
}

// 16-bit files (formats/fft16.md): the scene uploads the blocks as the
// reader expands them (version 16's layout) with the 181^2 (version 17) or
// 256^2 (version 16) frames of the code, and both decoders walk them as the
// scalar decoder does; scan goes 64 codes at a time through blocks of up to
// 254 (version 17's default) or more points.
TEST(ViewerGpuDecode, SixteenBitFilesMatchTheScalarDecoder) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string tck = shared_data("bundles/AF_L-step0.1.tck");
    const std::string v17 = compress16_into(dir, tck, "af17.fft", false);
    const std::string v16 = compress16_into(dir, tck, "af16.fftz", true);
    ASSERT_EQ(FftFile(v17).header().version, kFft16PackedVersion);
    ASSERT_EQ(FftFile(v16).header().version, kFft16Version);
    expect_gpu_decoders_match_scalar(v17, "AF_L version 17", 10000);
    expect_gpu_decoders_match_scalar(v16, "AF_L version 16 (.fftz)", 10000);
    // Blocks of 1000 points: 16 chunks of the scan decoder.
    expect_gpu_decoders_match_scalar(compress16_into(dir, tck, "af17-1000.fft", false, 1000), "AF_L version 17, 1000 points",
                                     10000);
}

TEST(ViewerGpuDecode, SixteenBitBlockBoundaryCases) {
    FIBLET_REQUIRE_GL();
    // Fibers whose blocks hold 1..3 points, 64 or 65 codes (one scan chunk,
    // or one more point), 128/129 codes, full 254-point blocks, and one point
    // more or less; a sharp turn.
    std::vector<std::vector<Vec3f>> fibers;
    for (int n : {1, 2, 3, 65, 66, 67, 130, 131, 253, 254, 255, 256, 508, 509}) {
        std::vector<Vec3f> f;
        for (int i = 0; i < n; ++i) {
            const float t = 0.05f * float(i) + 0.3f * float(n);
            f.push_back({10 * std::cos(t) + 0.1f * float(n), 10 * std::sin(t), 0.1f * float(i)});
        }
        fibers.push_back(f);
    }
    const float d = 0.51f;  // the helices' step: no resampling
    fibers.push_back({{0, 0, 0}, {d, 0, 0}, {d, d, 0}, {0, d, 0}, {0, d, d}});
    const TempDir dir;
    write_tck(dir.file("cases.tck"), fibers);
    for (const bool zstd : {false, true}) {
        const std::string fft = compress16_into(dir, dir.file("cases.tck"), zstd ? "cases.fftz" : "cases.fft", zstd);
        for (const auto kind : kBothDecoders) {
            SCOPED_TRACE(std::string(viewer::gpu_decoder_name(kind)) + (zstd ? " version 16" : " version 17"));
            const Comparison c = compare_decoders(fft, kind);
            EXPECT_EQ(c.points, FftFile(fft).header().points);
            EXPECT_LE(c.max_diff_mm, tolerance_mm(fft));
        }
    }
}

TEST(ViewerGpuDecode, SixteenBitTangentsAreTheUnitStepDirections) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const FftFile file(compress16_into(dir, shared_data("bundles/AF_L-step0.1.tck"), "af17.fft", false));
    const viewer::GpuScene scene(file, *viewer_gl().programs);
    expect_tangents_are_unit_step_directions(file, scene);
}
