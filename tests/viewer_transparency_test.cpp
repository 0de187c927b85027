// Transparency (apps/viewer/transparency/): every mode against an exact
// reference made here on the CPU: the same decoded segments projected with
// the same camera, rasterized by the diamond-exit rule the transparent lines
// use (diamond_exit.glsl), every fragment of a pixel sorted back to front and
// composited in double precision. A separated-in-depth scene, two real
// bundles at two opacities (the table of every mode is printed), fiber order
// invariance and determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include "cli_runner.hpp"
#include "scene/gpu_scene.hpp"
#include "window/orbit_camera.hpp"
#include "render/render_target.hpp"
#include "render/renderer.hpp"
#include "viewer_test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;

namespace {

constexpr int kSize = 256;

struct Segment {
    Vec3f p0, p1;
    std::uint32_t fiber;  // index in the file
};

// Every segment of every fiber, as the CPU reference decoder gives the
// points (fibers' blocks are consecutive; a fiber's points are its blocks').
std::vector<Segment> decoded_segments(const FftFile& file, const viewer::GpuScene& scene) {
    const CpuDecoded d = cpu_decode_blocks(file);
    std::vector<Segment> out;
    std::size_t point = 0;
    for (std::uint64_t f = 0; f < scene.fiber_count(); ++f) {
        const std::uint32_t n = scene.fiber_points(f);
        for (std::uint32_t k = 0; k + 1 < n; ++k)
            out.push_back({d.point(point + k), d.point(point + k + 1), std::uint32_t(f)});
        point += n;
    }
    return out;
}

// diamond_exit.glsl, the same float operations.
float diamond_distance(float px, float py, float cx, float cy) { return std::fabs(px - cx) + std::fabs(py - cy); }
bool exits_diamond(float ax, float ay, float bx, float by, float cx, float cy) {
    if (diamond_distance(bx, by, cx, cy) < 0.5f) return false;
    const float dx = bx - ax, dy = by - ay;
    float least = diamond_distance(ax, ay, cx, cy);
    if (dx != 0.0f) {
        const float t = std::clamp((cx - ax) / dx, 0.0f, 1.0f);
        least = std::min(least, diamond_distance(ax + t * dx, ay + t * dy, cx, cy));
    }
    if (dy != 0.0f) {
        const float t = std::clamp((cy - ay) / dy, 0.0f, 1.0f);
        least = std::min(least, diamond_distance(ax + t * dx, ay + t * dy, cx, cy));
    }
    return least < 0.5f;
}

struct Fragment {
    double depth;
    float r, g, b;
    double alpha;
};

// An image and the number of fragments of each pixel.
struct Reference {
    std::vector<std::uint8_t> rgba;
    std::vector<std::uint32_t> fragments;
};

// Each pixel's fragments blended far to near over black ("over", float64).
Reference composite_back_to_front(std::vector<std::vector<Fragment>>& pixels) {
    Reference ref{std::vector<std::uint8_t>(pixels.size() * 4, 255), std::vector<std::uint32_t>(pixels.size())};
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        auto& frags = pixels[i];
        std::stable_sort(frags.begin(), frags.end(), [](const Fragment& a, const Fragment& b) { return a.depth > b.depth; });
        double c[3] = {0, 0, 0};
        for (const Fragment& f : frags) {
            const float rgb[3] = {f.r, f.g, f.b};
            for (int k = 0; k < 3; ++k) c[k] = f.alpha * rgb[k] + (1 - f.alpha) * c[k];
        }
        for (int k = 0; k < 3; ++k) ref.rgba[4 * i + std::size_t(k)] = std::uint8_t(std::lround(std::clamp(c[k], 0.0, 1.0) * 255));
        ref.fragments[i] = std::uint32_t(frags.size());
    }
    return ref;
}

// The exact composite (RGBA8, rows from the top as RenderTarget::read_rgba)
// and the number of fragments of each pixel; colour by direction, no
// lighting, black background. With `fiber_alpha` (one per fiber) a fragment
// blends with opacity x its fiber's (the GPU's float product, fiber_colors.glsl).
Reference exact_reference(const std::vector<Segment>& segments, const Camera& cam, double opacity,
                          const std::vector<float>* fiber_alpha = nullptr) {
    const Mat4 vp = view_projection_matrix(cam);
    const Vec3f forward = [&] {
        const Vec3f d{cam.target.x - cam.position.x, cam.target.y - cam.position.y, cam.target.z - cam.position.z};
        const float n = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        return Vec3f{d.x / n, d.y / n, d.z / n};
    }();
    std::vector<std::vector<Fragment>> pixels(std::size_t(kSize) * kSize);
    for (const Segment& s : segments) {
        const auto c0 = clip_of(vp, s.p0), c1 = clip_of(vp, s.p1);
        if (c0[2] < -c0[3] || c1[2] < -c1[3]) continue;
        // GL window coordinates (rows from the bottom), as segment_quads.glsl.
        const float ax = (c0[0] / c0[3] * 0.5f + 0.5f) * float(kSize), ay = (c0[1] / c0[3] * 0.5f + 0.5f) * float(kSize);
        const float bx = (c1[0] / c1[3] * 0.5f + 0.5f) * float(kSize), by = (c1[1] / c1[3] * 0.5f + 0.5f) * float(kSize);
        const float dx = s.p1.x - s.p0.x, dy = s.p1.y - s.p0.y, dz = s.p1.z - s.p0.z;
        const float len = std::sqrt(dx * dx + dy * dy + dz * dz);
        if (!(len > 0)) continue;
        const Vec3f mid{(s.p0.x + s.p1.x) / 2, (s.p0.y + s.p1.y) / 2, (s.p0.z + s.p1.z) / 2};
        const double depth = double(mid.x - cam.position.x) * forward.x + double(mid.y - cam.position.y) * forward.y +
                             double(mid.z - cam.position.z) * forward.z;
        const double alpha = fiber_alpha ? double(float(opacity) * (*fiber_alpha)[s.fiber]) : opacity;
        const Fragment f{depth, std::fabs(dx / len), std::fabs(dy / len), std::fabs(dz / len), alpha};
        const int x0 = std::max(0, int(std::floor(std::min(ax, bx) - 1))), x1 = std::min(kSize - 1, int(std::max(ax, bx) + 1));
        const int y0 = std::max(0, int(std::floor(std::min(ay, by) - 1))), y1 = std::min(kSize - 1, int(std::max(ay, by) + 1));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x)
                if (exits_diamond(ax, ay, bx, by, float(x) + 0.5f, float(y) + 0.5f))
                    pixels[std::size_t(kSize - 1 - y) * kSize + std::size_t(x)].push_back(f);
    }
    return composite_back_to_front(pixels);
}

viewer::RenderOptions transparent_options(viewer::TransparencyMode mode, float opacity) {
    viewer::RenderOptions o;
    o.style = viewer::DrawStyle::lines;
    o.lighting = false;
    o.color_by_direction = true;
    o.opacity = opacity;
    o.transparency = mode;
    return o;
}

std::vector<std::uint8_t> render(const viewer::GpuScene& scene, const Camera& cam, const viewer::RenderOptions& o) {
    viewer::Renderer renderer(*viewer_gl().programs);
    viewer::RenderTarget target(kSize, kSize);
    renderer.render(scene, cam, o, target);
    return target.read_rgba();
}

// Error of an image against the reference over the pixels the reference
// covers (at least one fragment): the largest channel difference of each pixel.
struct ImageError {
    double mean = 0;        // /255
    double share_over_8 = 0;  // of the covered pixels, above 8/255
    int max = 0;
    std::size_t covered = 0;
};
ImageError image_error(const std::vector<std::uint8_t>& image, const Reference& ref) {
    ImageError e;
    double sum = 0;
    std::size_t over = 0;
    for (std::size_t i = 0; i < ref.fragments.size(); ++i) {
        int d = 0;
        for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(int(image[4 * i + std::size_t(k)]) - int(ref.rgba[4 * i + std::size_t(k)])));
        if (ref.fragments[i] == 0) {
            e.max = std::max(e.max, d);  // uncovered pixels must stay background
            continue;
        }
        ++e.covered;
        sum += d;
        over += d > 8;
        e.max = std::max(e.max, d);
    }
    e.mean = e.covered ? sum / double(e.covered) : 0;
    e.share_over_8 = e.covered ? double(over) / double(e.covered) : 0;
    return e;
}

Camera frontal_camera() {
    Camera cam;
    cam.position = {0, 0, 80};
    cam.target = {0, 0, 0};
    cam.up = {0, 1, 0};
    cam.fov_y_deg = 35;
    cam.aspect = 1;
    return cam;
}

// Three layers of straight fibers 10 mm apart in depth, each in one
// direction (colour), written nearest first so that unsorted blending is wrong.
std::vector<std::vector<Vec3f>> separated_layers() {
    std::vector<std::vector<Vec3f>> fibers;
    const Vec3f directions[3] = {{1, 0, 0}, {0, 1, 0}, {0.70710678f, 0.70710678f, 0}};
    const float depths[3] = {10, 0, -10};
    for (int layer = 0; layer < 3; ++layer)
        for (int i = 0; i < 12; ++i) {
            const Vec3f d = directions[layer];
            const Vec3f across{-d.y, d.x, 0};
            const float offset = -11.0f + 2.0f * float(i) + 0.37f * float(layer);
            std::vector<Vec3f> f;
            for (int k = 0; k <= 300; ++k) {
                const float t = -15.0f + 0.1f * float(k);
                f.push_back({t * d.x + offset * across.x, t * d.y + offset * across.y, depths[layer]});
            }
            fibers.push_back(f);
        }
    return fibers;
}

constexpr viewer::TransparencyMode kModes[] = {viewer::TransparencyMode::sorted, viewer::TransparencyMode::voxlines,
                                               viewer::TransparencyMode::unsorted};

}  // namespace

TEST(ViewerTransparency, DiamondExitLinesMatchTheReferenceCoverage) {
    // The pixels the GPU lights are exactly those the reference gives a
    // fragment (same rule, same points; every colour is non-black).
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(separated_layers());
    const FftFile& file = compressed.file;
    const viewer::GpuScene& scene = compressed.scene;
    const Camera cam = frontal_camera();
    const Reference ref = exact_reference(decoded_segments(file, scene), cam, 0.5);
    const auto image = render(scene, cam, transparent_options(viewer::TransparencyMode::unsorted, 0.5f));
    std::size_t covered = 0, mismatched = 0;
    for (std::size_t i = 0; i < ref.fragments.size(); ++i) {
        const bool lit = image[4 * i] || image[4 * i + 1] || image[4 * i + 2];
        covered += ref.fragments[i] > 0;
        mismatched += lit != (ref.fragments[i] > 0);
    }
    EXPECT_GT(covered, 3000u);
    EXPECT_EQ(mismatched, 0u);
}

TEST(ViewerTransparency, SeparatedInDepthMatchesTheReference) {
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(separated_layers());
    const FftFile& file = compressed.file;
    const viewer::GpuScene& scene = compressed.scene;
    const Camera cam = frontal_camera();
    const std::vector<Segment> segments = decoded_segments(file, scene);
    for (const float alpha : {0.2f, 0.5f}) {
        const Reference ref = exact_reference(segments, cam, alpha);
        for (const auto mode : kModes) {
            const ImageError e = image_error(render(scene, cam, transparent_options(mode, alpha)), ref);
            std::printf("separated layers, alpha %.2f, %-8s: max %d/255, mean %.3f/255 over %zu pixels\n", alpha,
                        viewer::transparency_mode_name(mode), e.max, e.mean, e.covered);
            if (mode == viewer::TransparencyMode::unsorted) {
                EXPECT_GT(e.max, 8) << "the scene does not tell orders apart";
            } else {
                EXPECT_LE(e.max, 2) << viewer::transparency_mode_name(mode) << " alpha " << alpha;
            }
        }
    }
}

namespace {

struct BundleCase {
    const char* name;
    std::vector<std::vector<Vec3f>> fibers;
};

std::vector<BundleCase> real_bundles() {
    const std::string data = std::string(FIBLET_SHARED_DIR) + "/data/";
    auto sdstream = read_tck_fibers(data + "small-sdstream.tck");
    sdstream.resize(std::min<std::size_t>(sdstream.size(), 300));
    return {{"AF_L-step0.1", read_tck_fibers(data + "bundles/AF_L-step0.1.tck")}, {"small-sdstream[0:300]", sdstream}};
}

}  // namespace

namespace {

void print_table_header() {
    std::printf("%-22s %5s %-9s %11s %13s %8s %10s\n", "scene", "alpha", "mode", "mean /255", "> 8/255 (%)",
                "max", "vs unsorted");
}

// One row per mode (kModes' order) of the table; with `check`, the issue's
// bounds for the ordered modes.
void report_modes(const std::string& name, float alpha, const ImageError (&errors)[3], bool check) {
    const ImageError& unsorted = errors[2];
    for (int m = 0; m < 3; ++m) {
        const ImageError& e = errors[m];
        std::printf("%-22s %5.2f %-9s %11.3f %13.3f %8d %10.3f\n", name.c_str(), alpha,
                    viewer::transparency_mode_name(kModes[m]), e.mean, 100 * e.share_over_8, e.max,
                    unsorted.mean > 0 ? e.mean / unsorted.mean : 0.0);
        if (!check || kModes[m] == viewer::TransparencyMode::unsorted) continue;
        SCOPED_TRACE(name + " " + viewer::transparency_mode_name(kModes[m]) + " alpha " + std::to_string(alpha));
        EXPECT_LE(e.mean, 1.0);
        EXPECT_LE(e.share_over_8, 0.01);
        EXPECT_LE(e.mean, 0.25 * unsorted.mean);
    }
}

// Every mode against the exact reference at both opacities, printed; with
// `check`, the bounds for the ordered modes.
void compare_modes(const TempDir& dir, const BundleCase& bundle, bool check) {
    ASSERT_FALSE(bundle.fibers.empty()) << bundle.name;
    const FftFile file(compress_fibers(dir, bundle.fibers, "b"));
    const viewer::GpuScene scene(file, *viewer_gl().programs);
    const Camera cam = viewer::camera_from_spec("oblique", scene, 1.0f, 35, 1);
    const std::vector<Segment> segments = decoded_segments(file, scene);
    for (const float alpha : {0.05f, 0.2f}) {
        const Reference ref = exact_reference(segments, cam, alpha);
        ImageError errors[3];
        for (int m = 0; m < 3; ++m) errors[m] = image_error(render(scene, cam, transparent_options(kModes[m], alpha)), ref);
        report_modes(bundle.name, alpha, errors, check);
    }
}

}  // namespace

TEST(ViewerTransparency, RealBundlesMatchTheExactReference) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    print_table_header();
    for (const BundleCase& bundle : real_bundles()) compare_modes(dir, bundle, true);
}

// The whole small-ifod1.tck (2000 fibers, 1.8 M segments; the issue's own
// measurement): a table only, run by hand (a minute on llvmpipe):
// fiblet_tests --gtest_also_run_disabled_tests --gtest_filter='*WholeSmallIfod1*'
TEST(ViewerTransparency, DISABLED_WholeSmallIfod1Table) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    print_table_header();
    compare_modes(dir, {"small-ifod1", read_tck_fibers(shared_data("small-ifod1.tck"))}, false);
}

// Per-fiber opacities (--fiber-opacity): random ones in [0, 1] on a shared
// bundle, times a global opacity; the reference blends every fragment with
// its fiber's product. The ordered modes meet the bounds.
TEST(ViewerTransparency, PerFiberOpacityMatchesTheExactReference) {
    FIBLET_REQUIRE_GL();
    CompressedScene compressed(read_tck_fibers(std::string(FIBLET_SHARED_DIR) + "/data/bundles/AF_L-step0.1.tck"));
    const FftFile& file = compressed.file;
    viewer::GpuScene& scene = compressed.scene;
    ASSERT_GT(scene.fiber_count(), 10u);
    std::mt19937 rng(1616);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    std::vector<float> alpha(scene.fiber_count());
    for (float& a : alpha) a = uniform(rng);
    scene.set_fiber_opacities(alpha);
    const Camera cam = viewer::camera_from_spec("oblique", scene, 1.0f, 35, 1);
    const std::vector<Segment> segments = decoded_segments(file, scene);
    print_table_header();
    for (const float global : {0.2f, 1.0f}) {
        const Reference ref = exact_reference(segments, cam, global, &alpha);
        ImageError errors[3];
        for (int m = 0; m < 3; ++m) {
            auto o = transparent_options(kModes[m], global);
            o.fiber_opacity = true;
            errors[m] = image_error(render(scene, cam, o), ref);
        }
        report_modes("AF_L-step0.1 x U(0,1)", global, errors, true);
    }
}

TEST(ViewerTransparency, AFiberOfOpacityZeroDisappears) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const auto fibers = read_tck_fibers(std::string(FIBLET_SHARED_DIR) + "/data/bundles/AF_L-step0.1.tck");
    ASSERT_GT(fibers.size(), 10u);
    const FftFile file(compress_fibers(dir, fibers, "b"));
    viewer::GpuScene scene(file, *viewer_gl().programs);
    const std::uint64_t last = scene.fiber_count() - 1;
    ASSERT_EQ(scene.fiber_id(last), last);
    std::vector<float> alpha(scene.fiber_count(), 1.0f);
    alpha[last] = 0;
    scene.set_fiber_opacities(alpha);
    const Camera cam = viewer::camera_from_spec("oblique", scene, 1.0f, 35, 1);
    const std::vector<Segment> segments = decoded_segments(file, scene);
    std::vector<Segment> others, gone;
    for (const Segment& seg : segments) (seg.fiber == last ? gone : others).push_back(seg);
    const Reference without = exact_reference(others, cam, 0.3), only = exact_reference(gone, cam, 0.3);
    for (const auto mode : kModes) {
        SCOPED_TRACE(viewer::transparency_mode_name(mode));
        auto o = transparent_options(mode, 0.3f);
        o.fiber_opacity = true;
        const auto image = render(scene, cam, o);
        // Every pixel the fiber alone covers stays background.
        std::size_t its_own = 0, lit = 0;
        for (std::size_t i = 0; i < only.fragments.size(); ++i)
            if (only.fragments[i] > 0 && without.fragments[i] == 0) {
                ++its_own;
                lit += image[4 * i] || image[4 * i + 1] || image[4 * i + 2];
            }
        EXPECT_GT(its_own, 20u);
        EXPECT_EQ(lit, 0u);
        const ImageError e = image_error(image, without);
        std::printf("last fiber at opacity 0, %-8s: %zu of its own pixels lit of %zu; against the reference without "
                    "it mean %.3f/255, %.3f %% above 8/255\n",
                    viewer::transparency_mode_name(mode), lit, its_own, e.mean, 100 * e.share_over_8);
        if (mode == viewer::TransparencyMode::unsorted) continue;
        EXPECT_LE(e.mean, 1.0);
        EXPECT_LE(e.share_over_8, 0.01);
        if (mode != viewer::TransparencyMode::sorted) continue;
        // Sorted keys chunks by block and the scene's box: leaving the fiber
        // out by ID blends the same fragments in the same order.
        auto subset = transparent_options(mode, 0.3f);
        subset.id_max = std::uint32_t(last - 1);
        EXPECT_EQ(image, render(scene, cam, subset));
    }
}

TEST(ViewerTransparency, FiberOpacitiesOfOneAreTheGlobalOpacity) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    auto fibers = read_tck_fibers(std::string(FIBLET_SHARED_DIR) + "/data/small-sdstream.tck");
    fibers.resize(300);
    const FftFile file(compress_fibers(dir, fibers, "s"));
    viewer::GpuScene scene(file, *viewer_gl().programs);
    scene.set_fiber_opacities(std::vector<float>(scene.fiber_count(), 1.0f));
    const Camera cam = viewer::camera_from_spec("oblique", scene, 1.0f, 35, 1);
    for (const auto mode : kModes) {
        auto o = transparent_options(mode, 0.2f);
        o.lighting = true;
        o.frustum_culling = mode != viewer::TransparencyMode::unsorted;  // as TwoRendersAreByteIdentical
        auto per_fiber = o;
        per_fiber.fiber_opacity = true;
        EXPECT_EQ(render(scene, cam, per_fiber), render(scene, cam, o)) << viewer::transparency_mode_name(mode);
    }
    EXPECT_THROW(scene.set_fiber_opacities({0.5f}), Error);
    std::vector<float> bad(scene.fiber_count(), 0.5f);
    bad[7] = 1.5f;
    EXPECT_THROW(scene.set_fiber_opacities(bad), Error);
}

namespace {

// Entry distance of the unit ray (o, d) into the capsule of segment a-b and
// radius r (the union of the cylinder between the end planes and the two
// end spheres, as capsules.frag.glsl), or infinity; double precision.
double capsule_entry(const std::array<double, 3>& o, const std::array<double, 3>& d, Vec3f pa, Vec3f pb, double r) {
    using V = std::array<double, 3>;
    auto dot3 = [](const V& u, const V& v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
    const V a{pa.x, pa.y, pa.z}, b{pb.x, pb.y, pb.z};
    const V ba{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, oa{o[0] - a[0], o[1] - a[1], o[2] - a[2]};
    double best = INFINITY;
    const double baba = dot3(ba, ba), bard = dot3(ba, d), baoa = dot3(ba, oa);
    const double qa = baba - bard * bard;
    if (qa > 1e-12 * baba) {
        const double qb = baba * dot3(d, oa) - baoa * bard, qc = baba * dot3(oa, oa) - baoa * baoa - r * r * baba;
        const double h = qb * qb - qa * qc;
        if (h >= 0) {
            const double t = (-qb - std::sqrt(h)) / qa, y = baoa + t * bard;
            if (y > 0 && y < baba && t > 0) best = t;
        }
    }
    for (const V& c : {a, b}) {
        const V oc{o[0] - c[0], o[1] - c[1], o[2] - c[2]};
        const double bb = dot3(d, oc), h = bb * bb - (dot3(oc, oc) - r * r);
        if (h >= 0 && -bb - std::sqrt(h) > 0) best = std::min(best, -bb - std::sqrt(h));
    }
    return best;
}

// The exact composite of what the capsules style blends: every capsule's
// entry on each pixel's ray (one per capsule, as its box's front faces give
// one fragment), sorted back to front; colour by direction, no lighting.
Reference capsule_reference(const std::vector<Segment>& segments, const Camera& cam, double radius, double opacity) {
    const Mat4 vp = view_projection_matrix(cam);
    const Vec3f eye = cam.position;
    const std::array<double, 3> o{eye.x, eye.y, eye.z};
    std::vector<std::vector<Fragment>> pixels(std::size_t(kSize) * kSize);
    for (const Segment& s : segments) {
        const float dx = s.p1.x - s.p0.x, dy = s.p1.y - s.p0.y, dz = s.p1.z - s.p0.z;
        const float len = std::sqrt(dx * dx + dy * dy + dz * dz);
        if (!(len > 0)) continue;
        // The pixels of the capsule's box on screen (rows from the top), a pixel more.
        float lo_x = INFINITY, hi_x = -INFINITY, lo_y = INFINITY, hi_y = -INFINITY;
        bool behind = false;
        for (int corner = 0; corner < 8; ++corner) {
            const float r = float(radius);
            const Vec3f p{(corner & 1 ? std::max(s.p0.x, s.p1.x) + r : std::min(s.p0.x, s.p1.x) - r),
                          (corner & 2 ? std::max(s.p0.y, s.p1.y) + r : std::min(s.p0.y, s.p1.y) - r),
                          (corner & 4 ? std::max(s.p0.z, s.p1.z) + r : std::min(s.p0.z, s.p1.z) - r)};
            const auto c = clip_of(vp, p);
            if (c[3] <= 0) behind = true;
            const float x = (c[0] / c[3] * 0.5f + 0.5f) * float(kSize), y = (0.5f - c[1] / c[3] * 0.5f) * float(kSize);
            lo_x = std::min(lo_x, x), hi_x = std::max(hi_x, x), lo_y = std::min(lo_y, y), hi_y = std::max(hi_y, y);
        }
        if (behind) continue;
        const Fragment f{0, std::fabs(dx / len), std::fabs(dy / len), std::fabs(dz / len), opacity};
        for (int y = std::max(0, int(lo_y) - 1); y <= std::min(kSize - 1, int(hi_y) + 1); ++y)
            for (int x = std::max(0, int(lo_x) - 1); x <= std::min(kSize - 1, int(hi_x) + 1); ++x) {
                const double t = capsule_entry(o, camera_pixel_ray(cam, x, y, kSize, kSize), s.p0, s.p1, radius);
                if (!std::isfinite(t)) continue;
                Fragment g = f;
                g.depth = t;
                pixels[std::size_t(y) * kSize + std::size_t(x)].push_back(g);
            }
    }
    return composite_back_to_front(pixels);
}

}  // namespace

// Sorted chunks through the ray-cast styles: three layers 10 mm apart
// written nearest first, drawn sorted, against the same layers written
// farthest first and blended unsorted in file order (the right order:
// tubes of a layer do not overlap, and a fiber's overlapping pieces have
// one colour).
TEST(ViewerTransparency, SortedTubesAndCapsulesBlendBackToFront) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    auto fibers = separated_layers();
    write_tck(dir.file("near.tck"), fibers);
    std::reverse(fibers.begin(), fibers.end());
    write_tck(dir.file("far.tck"), fibers);
    const FftFile near_first(compress_into(dir, dir.file("near.tck"), "near.fft"));
    const FftFile far_first(compress_into(dir, dir.file("far.tck"), "far.fft"));
    const viewer::GpuScene near_scene(near_first, *viewer_gl().programs), far_scene(far_first, *viewer_gl().programs);
    const Camera cam = frontal_camera();
    for (const auto style : {viewer::DrawStyle::tubes, viewer::DrawStyle::capsules}) {
        SCOPED_TRACE(viewer::draw_style_name(style));
        auto o = transparent_options(viewer::TransparencyMode::sorted, 0.3f);
        o.style = style;
        o.tube_radius_mm = 0.3f;
        auto right = o;
        right.transparency = viewer::TransparencyMode::unsorted;
        right.frustum_culling = false;  // file order
        const auto expected = render(far_scene, cam, right);
        const auto sorted = render(near_scene, cam, o);
        auto wrong = right;
        const auto unsorted = render(near_scene, cam, wrong);
        int sorted_max = 0, unsorted_max = 0;
        std::size_t lit = 0;
        for (std::size_t i = 0; i < expected.size(); ++i) {
            sorted_max = std::max(sorted_max, std::abs(int(sorted[i]) - int(expected[i])));
            unsorted_max = std::max(unsorted_max, std::abs(int(unsorted[i]) - int(expected[i])));
            lit += i % 4 == 0 && (expected[i] || expected[i + 1] || expected[i + 2]);
        }
        std::printf("separated layers, %-8s: sorted (nearest first) vs back to front: max %d/255; unsorted %d/255; "
                    "%zu pixels lit\n",
                    viewer::draw_style_name(style), sorted_max, unsorted_max, lit);
        EXPECT_GT(lit, 5000u);
        EXPECT_LE(sorted_max, 2);
        EXPECT_GT(unsorted_max, 8);
        EXPECT_EQ(sorted, render(near_scene, cam, o)) << "two sorted renders differ";
    }
}

// Sorted capsules on a real bundle against the exact composite of every
// capsule entry (capsule_reference).
TEST(ViewerTransparency, SortedCapsulesMatchTheExactReference) {
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(read_tck_fibers(std::string(FIBLET_SHARED_DIR) + "/data/bundles/AF_L-step0.1.tck"));
    const FftFile& file = compressed.file;
    const viewer::GpuScene& scene = compressed.scene;
    const Camera cam = viewer::camera_from_spec("oblique", scene, 1.0f, 35, 1);
    const std::vector<Segment> segments = decoded_segments(file, scene);
    constexpr float kRadius = 0.3f;
    print_table_header();
    for (const float alpha : {0.05f, 0.2f}) {
        const Reference ref = capsule_reference(segments, cam, kRadius, alpha);
        ImageError errors[3];
        for (int m = 0; m < 3; ++m) {
            if (kModes[m] == viewer::TransparencyMode::voxlines) continue;  // lines only
            auto o = transparent_options(kModes[m], alpha);
            o.style = viewer::DrawStyle::capsules;
            o.tube_radius_mm = kRadius;
            errors[m] = image_error(render(scene, cam, o), ref);
        }
        const ImageError &sorted = errors[0], &unsorted = errors[2];
        for (const int m : {0, 2})
            std::printf("%-22s %5.2f %-9s %11.3f %13.3f %8d %10.3f\n", "AF_L capsules r 0.3", alpha,
                        viewer::transparency_mode_name(kModes[m]), errors[m].mean, 100 * errors[m].share_over_8,
                        errors[m].max, unsorted.mean > 0 ? errors[m].mean / unsorted.mean : 0.0);
        // Measured (llvmpipe): 0.28 / 0.017 % at alpha 0.05 (the line
        // bounds), 1.22 / 1.7 % at 0.2: tubes 0.6 mm wide touch, and 1 mm
        // chunks do not order their interleaved entries; asserted with margin.
        SCOPED_TRACE("alpha " + std::to_string(alpha));
        EXPECT_GT(sorted.covered, 5000u);
        EXPECT_LE(sorted.mean, alpha < 0.1f ? 1.0 : 1.5);
        EXPECT_LE(sorted.share_over_8, alpha < 0.1f ? 0.01 : 0.025);
        EXPECT_LE(sorted.mean, 0.15 * unsorted.mean);
    }
}

TEST(ViewerTransparency, FiberOrderDoesNotChangeASortedImage) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    auto fibers = read_tck_fibers(std::string(FIBLET_SHARED_DIR) + "/data/bundles/AF_L-step0.1.tck");
    write_tck(dir.file("a.tck"), fibers);
    std::mt19937 rng(16);
    std::shuffle(fibers.begin(), fibers.end(), rng);
    write_tck(dir.file("b.tck"), fibers);
    const FftFile a(compress_into(dir, dir.file("a.tck"), "a.fft")), b(compress_into(dir, dir.file("b.tck"), "b.fft"));
    const viewer::GpuScene scene_a(a, *viewer_gl().programs), scene_b(b, *viewer_gl().programs);
    const Camera cam = viewer::camera_from_spec("oblique", scene_a, 1.0f, 35, 1);
    const Reference ref = exact_reference(decoded_segments(a, scene_a), cam, 0.2);
    for (const auto mode : {viewer::TransparencyMode::sorted, viewer::TransparencyMode::voxlines}) {
        const auto o = transparent_options(mode, 0.2f);
        const auto image_a = render(scene_a, cam, o), image_b = render(scene_b, cam, o);
        // The shuffled image against the first as a reference of its own: within the tolerance of the modes.
        Reference first{image_a, ref.fragments};
        const ImageError e = image_error(image_b, first);
        std::printf("shuffled fibers, %s: mean %.3f/255, %.3f %% above 8/255\n", viewer::transparency_mode_name(mode),
                    e.mean, 100 * e.share_over_8);
        EXPECT_LE(e.mean, 1.0) << viewer::transparency_mode_name(mode);
        EXPECT_LE(e.share_over_8, 0.01) << viewer::transparency_mode_name(mode);
    }
}

TEST(ViewerTransparency, TwoRendersAreByteIdentical) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    auto fibers = read_tck_fibers(std::string(FIBLET_SHARED_DIR) + "/data/small-sdstream.tck");
    fibers.resize(300);
    const FftFile file(compress_fibers(dir, fibers, "s"));
    const viewer::GpuScene scene(file, *viewer_gl().programs);
    const Camera cam = viewer::camera_from_spec("oblique", scene, 1.0f, 35, 1);
    for (const auto mode : kModes) {
        auto o = transparent_options(mode, 0.2f);
        o.lighting = true;
        // Unsorted blends in the culling pass's list order, which its atomics
        // vary: deterministic without the list only.
        o.frustum_culling = mode != viewer::TransparencyMode::unsorted;
        for (int repeat = 0; repeat < 2; ++repeat)
            EXPECT_EQ(render(scene, cam, o), render(scene, cam, o)) << viewer::transparency_mode_name(mode);
    }
}

TEST(ViewerTransparency, CliOptions) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string fft = compress_into(dir, shared_data("bundles/AF_L.tck"), "af.fft");
    for (const char* bad : {"--opacity 0", "--opacity 1.5", "--opacity 0.5 --transparency depth",
                            "--opacity 0.5 --transparency voxlines --style tubes",
                            "--opacity 0.5 --transparency voxlines --style capsules"}) {
        const CommandResult r = run_cli("render " + fft + " -o " + dir.file("x.png") + " --size 32x32 " + bad);
        EXPECT_EQ(r.status, 2) << bad << ": " << r.output;
        EXPECT_FALSE(std::filesystem::exists(dir.file("x.png"))) << bad;
    }
    for (const char* good : {"--opacity 0.3", "--opacity 0.3 --transparency voxlines",
                             "--opacity 0.3 --transparency unsorted --style tubes",
                             "--opacity 0.3 --transparency sorted --style tubes",
                             "--opacity 0.3 --style capsules"}) {
        const CommandResult r = run_cli("render " + fft + " -o " + dir.file("y.png") + " -f --size 64x48 " + good);
        EXPECT_EQ(r.status, 0) << good << ": " << r.output;
    }
    // --fiber-opacity: one value in [0, 1] per streamline, a file or dps/NAME.
    const FftFile file(fft);
    std::string alpha, over;
    for (std::uint64_t f = 0; f < file.header().fibers; ++f) {
        alpha += f % 3 ? "0.5\n" : "0\n";
        over += f == 3 ? "1.5\n" : "1\n";
    }
    write_file(dir.file("alpha.txt"), alpha);
    write_file(dir.file("over.txt"), over);
    write_file(dir.file("short.txt"), "0.5\n");
    const std::string common = "render " + fft + " -o " + dir.file("z.png") + " -f --size 64x48 ";
    for (const std::string& good : {"--fiber-opacity " + dir.file("alpha.txt"),
                                   "--fiber-opacity " + dir.file("alpha.txt") + " --opacity 0.5 --style capsules",
                                   "--fiber-opacity " + dir.file("alpha.txt") + " --engine voxel-rt --grid 16"}) {
        const CommandResult r = run_cli(common + good);
        EXPECT_EQ(r.status, 0) << good << ": " << r.output;
    }
    for (const auto& [bad, status] : std::vector<std::pair<std::string, int>>{
             {"--fiber-opacity " + dir.file("over.txt"), 4},
             {"--fiber-opacity " + dir.file("short.txt"), 4},
             {"--fiber-opacity dps/weight", 2},
             {"--fiber-opacity " + dir.file("missing.txt"), 2}}) {
        const CommandResult r = run_cli(common + bad);
        EXPECT_EQ(r.status, status) << bad << ": " << r.output;
    }
    const CommandResult bench =
        run_cli("render " + fft + " --bench --frames 1 --size 64x48 --json --opacity 0.2 --transparency sorted");
    ASSERT_EQ(bench.status, 0) << bench.output;
    for (const char* key : {"\"transparency\"", "\"opaque_frame_ms\"", "\"gpu_bytes\"", "\"sorted\""})
        EXPECT_NE(bench.output.find(key), std::string::npos) << key << " in " << bench.output;
}
