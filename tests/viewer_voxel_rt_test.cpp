// The voxel ray tracer (apps/viewer/voxel_rt): its conservative capsule
// voxelization (CPU against sampled capsule points, GPU against the CPU
// exactly, and the non-conservative widening as a negative check), its
// opaque images against Intel Embree's round linear curves (the same
// capsules), and its ambient occlusion.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <numeric>
#include <random>
#include <unordered_set>

#include "cli_runner.hpp"
#include "scene/gpu_scene.hpp"
#include "gl/png_file.hpp"
#include "window/orbit_camera.hpp"
#include "render/render_target.hpp"
#include "render/renderer.hpp"
#include "viewer_test_util.hpp"
#include "voxel_rt/capsule_voxelization.hpp"
#include "voxel_rt/voxel_structure.hpp"

#if FIBLET_HAS_EMBREE
#include "embree_capsules.hpp"
#endif

using namespace fiblet;
using namespace fiblet::test;
namespace vrt = fiblet::viewer::voxel_rt;

namespace {

struct Capsule {
    std::array<float, 3> a, b;
};

constexpr int kGrid = 64;

// Capsules in voxel units inside the grid: random ends up to 12 voxels
// apart, in every direction.
std::vector<Capsule> random_capsules(std::size_t count, float radius, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(radius + 0.01f, float(kGrid) - radius - 0.01f), off(-6.0f, 6.0f);
    std::vector<Capsule> out;
    while (out.size() < count) {
        Capsule c;
        for (int k = 0; k < 3; ++k) c.a[k] = pos(rng), c.b[k] = c.a[k] + off(rng);
        bool inside = true;
        for (int k = 0; k < 3; ++k) inside &= c.b[k] > radius && c.b[k] < float(kGrid) - radius;
        if (inside) out.push_back(c);
    }
    return out;
}

// Points of the capsule: half inside, half on its surface.
std::vector<std::array<float, 3>> sample_capsule(const Capsule& c, float r, std::mt19937& rng, int count) {
    std::normal_distribution<float> g;
    std::uniform_real_distribution<float> u(0, 1);
    std::vector<std::array<float, 3>> out;
    for (int i = 0; i < count; ++i) {
        const float t = u(rng);
        float v[3] = {g(rng), g(rng), g(rng)};
        const float n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        const float len = (i % 2 ? std::cbrt(u(rng)) : 0.99999f) * r / std::max(n, 1e-6f);
        std::array<float, 3> p;
        for (int k = 0; k < 3; ++k) p[k] = c.a[k] + t * (c.b[k] - c.a[k]) + v[k] * len;
        out.push_back(p);
    }
    return out;
}

// Sampled capsule points whose voxel the voxelization did not visit.
std::size_t missed_voxels(const std::vector<Capsule>& capsules, float r, vrt::HalfExtentRule rule,
                          std::size_t& capsules_missing) {
    std::mt19937 rng(7);
    std::size_t missed = 0;
    capsules_missing = 0;
    for (const Capsule& c : capsules) {
        std::unordered_set<int> visited;
        vrt::for_each_capsule_voxel(c.a, c.b, r, kGrid,
                                    [&](int x, int y, int z) { visited.insert((z * kGrid + y) * kGrid + x); }, rule);
        std::size_t here = 0;
        for (const auto& p : sample_capsule(c, r, rng, 400)) {
            const int x = int(std::floor(p[0])), y = int(std::floor(p[1])), z = int(std::floor(p[2]));
            here += !visited.count((z * kGrid + y) * kGrid + x);
        }
        missed += here;
        capsules_missing += here > 0;
    }
    return missed;
}

const float kRadii[] = {0.1f, 0.2f, 0.7f, 2.5f};  // voxels; 2500 capsules each

}  // namespace

TEST(VoxelRtVoxelization, EveryVoxelOfASampledCapsulePointIsVisited) {
    std::size_t missed = 0, naive_missed = 0, naive_capsules = 0, total = 0;
    for (float r : kRadii) {
        const auto capsules = random_capsules(2500, r, std::uint32_t(r * 1000));
        std::size_t bad = 0, naive_bad = 0;
        missed += missed_voxels(capsules, r, vrt::HalfExtentRule::ellipse, bad);
        naive_missed += missed_voxels(capsules, r, vrt::HalfExtentRule::radius_only, naive_bad);
        naive_capsules += naive_bad;
        total += capsules.size();
    }
    std::printf("%zu capsules: exact half-extent misses %zu sampled points; widening by r alone misses %zu "
                "points of %zu capsules\n",
                total, missed, naive_missed, naive_capsules);
    EXPECT_EQ(missed, 0u);
    // The negative check: widening the minor axes by r alone is not conservative.
    EXPECT_GT(naive_capsules, 0u);
}

TEST(VoxelRtVoxelization, GpuCountsEqualTheCpuImplementation) {
    FIBLET_REQUIRE_GL();
    const vrt::VoxelRtPrograms programs;
    vrt::VoxelGrid grid;
    grid.n = kGrid, grid.voxel_mm = 1, grid.origin = {0, 0, 0};
    std::size_t voxels_compared = 0, differing = 0;
    std::uint64_t visits = 0;
    for (float r : kRadii) {
        const auto capsules = random_capsules(2500, r, std::uint32_t(r * 1000));
        std::vector<float> points;  // one slot of two points per capsule
        std::vector<std::uint32_t> cpu(std::size_t(kGrid) * kGrid * kGrid, 0);
        for (const Capsule& c : capsules) {
            points.insert(points.end(), {c.a[0], c.a[1], c.a[2], 1, c.b[0], c.b[1], c.b[2], 1});
            vrt::for_each_capsule_voxel(c.a, c.b, r, kGrid, [&](int x, int y, int z) {
                ++cpu[std::size_t((z * kGrid + y) * kGrid + x)];
            });
        }
        const viewer::GlBuffer buffer = viewer::make_buffer(GLsizeiptr(points.size() * 4), points.data(), 0);
        const vrt::ResidentSegments segments{buffer.get(), std::uint32_t(capsules.size()), 1, nullptr};
        const vrt::VoxelStructure structure(programs, grid, segments, r, false);
        const auto cells = structure.read_cells();
        for (std::size_t v = 0; v < cpu.size(); ++v) {
            differing += (cells[v] & 0xffffu) != cpu[v];
            visits += cpu[v];
        }
        voxels_compared += cpu.size();
        EXPECT_EQ(structure.fragment_count(), std::accumulate(cpu.begin(), cpu.end(), std::uint64_t(0)));
    }
    std::printf("GPU vs CPU voxelization: %zu voxels, %zu differ (%llu visits)\n", voxels_compared, differing,
                static_cast<unsigned long long>(visits));
    EXPECT_EQ(differing, 0u);
}

namespace {

// A render of the voxel ray tracer (on a 64³ grid unless the options say
// otherwise) with segment IDs in the fiber buffer.
struct TracedImage {
    std::vector<std::uint32_t> segments;  // segment + 1, 0 = background
    std::vector<std::uint8_t> rgba;
    std::vector<float> depth;  // window depth
};
TracedImage trace_image(const viewer::GpuScene& scene, const Camera& cam, int w, int h, viewer::RenderOptions o) {
    if (o.voxel_grid == viewer::RenderOptions{}.voxel_grid) o.voxel_grid = 64;
    viewer::Renderer renderer(*viewer_gl().programs);
    renderer.voxel_ray_tracer().write_segment_ids(true);
    viewer::RenderTarget target(w, h);
    o.engine = viewer::RenderEngine::voxel_rt;
    renderer.render(scene, cam, o, target);
    return {target.read_fibers(), target.read_rgba(), target.read_depth()};
}

}  // namespace

#if FIBLET_HAS_EMBREE
namespace {

// An opaque w × h voxel-rt image against the oracle's nearest hits: hit/miss
// agreement and the same hit segment. The residual disagreements are
// reported with how far the hit lies from where the two segments' parts of
// the tube meet, when they are neighbours at the same depth (within
// joint_mm): the planes through their joint normal to the later segment
// (sphere | cylinder) and to the sum of their unit directions (where their
// cylinders cross).
void expect_opaque_agreement(const viewer::GpuScene& scene, const EmbreeCapsules& oracle, const char* view,
                             const viewer::RenderOptions& o, double joint_mm) {
    const int w = 200, h = 200;
    const Camera cam = viewer::camera_from_spec(view, scene, 1.0f, 35, 2.0f);
    const TracedImage img = trace_image(scene, cam, w, h, o);
    std::size_t agree = 0, hits = 0, both = 0, same = 0, joint = 0;
    double farthest_from_edge = 0;
    const double n = cam.near_mm, f = cam.far_mm, tt = std::tan(double(cam.fov_y_deg) * M_PI / 360.0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const auto dir = camera_pixel_ray(cam, x, y, w, h);
            const auto ref = oracle.nearest(cam.position, dir);
            const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
            const std::uint32_t got = img.segments[i];
            const bool hit = std::isfinite(ref.t);
            hits += hit;
            agree += hit == (got != 0);
            if (!hit || got == 0) continue;
            ++both;
            if (got - 1 == ref.segment) {
                ++same;
                continue;
            }
            const double z_gpu = 2 * n * f / ((f + n) - (2.0 * img.depth[i] - 1.0) * (f - n));
            const double nx = (x + 0.5) / w * 2 - 1, ny = 1 - (y + 0.5) / h * 2;
            const double cosine = 1.0 / std::sqrt(1 + nx * nx * tt * tt * cam.aspect * cam.aspect + ny * ny * tt * tt);
            if (!oracle.consecutive(got - 1, ref.segment) || std::fabs(ref.t * cosine - z_gpu) > joint_mm) continue;
            ++joint;
            auto [a0, a1] = oracle.ends(got - 1);
            auto [b0, b1] = oracle.ends(ref.segment);
            if (a1.x != b0.x || a1.y != b0.y || a1.z != b0.z) std::swap(a0, b0), std::swap(a1, b1);
            auto unit = [](const Vec3f& from, const Vec3f& to) {
                const double v[3] = {double(to.x) - from.x, double(to.y) - from.y, double(to.z) - from.z};
                const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
                return std::array<double, 3>{v[0] / l, v[1] / l, v[2] / l};
            };
            const auto ua = unit(a0, a1), ub = unit(b0, b1);
            const double p[3] = {cam.position.x + ref.t * dir[0] - a1.x, cam.position.y + ref.t * dir[1] - a1.y,
                                 cam.position.z + ref.t * dir[2] - a1.z};
            double to_b = 0, to_crossing = 0, sum = 0;
            for (int c = 0; c < 3; ++c) {
                to_b += p[c] * ub[c], to_crossing += p[c] * (ua[c] + ub[c]);
                sum += (ua[c] + ub[c]) * (ua[c] + ub[c]);
            }
            farthest_from_edge =
                std::max(farthest_from_edge, std::min(std::fabs(to_b), std::fabs(to_crossing) / std::sqrt(sum)));
        }
    const double rate = double(agree) / double(w * h), strict = double(same) / double(both);
    std::printf("%s%s: voxel-rt vs Embree, %d pixels (%zu hit): hit/miss %.5f, same segment %.5f; of the %zu others, "
                "%zu the neighbour's hit at the same depth, at most %.2g mm from the edge of their parts\n",
                view, o.fiber_radii ? " (per-fiber radii)" : "", w * h, hits, rate, strict, both - same, joint,
                farthest_from_edge);
    EXPECT_GT(hits, 2000u);
    EXPECT_GE(rate, 0.999);
    EXPECT_GE(strict, 0.995);
}

// Whether the oracle's entries along a pixel's ray (the fibers entered, in
// order) change when the ray's direction turns by kRayTurn towards either
// side of two axes across it: the ray passes within ~kRayTurn · t of a
// tube's silhouette (or of where two stretches of one tube meet), closer
// than the renderer's ray can be placed. The shader's direction is float
// arithmetic on float camera vectors (normalize(forward + ndc.x · ...)):
// emulated on the CPU for the 160² rays of the transparency tests, it lies
// up to 1.7e-7 rad from the test's double one (≈ 2e-5 mm at the scene's
// ~110 mm), so which of the two rays enters a tube it grazes closer than
// that is a tie neither side decides (CST_R, 160², r 0.6 mm: one ray dips
// 2.9e-6 mm into a cylinder it grazes, the shader's passes 4.0e-6 mm
// outside; 11/255 at α 0.25). kRayTurn is ~6× the measured offset, the
// same 1e-6 of the distance that the oracle takes as float noise
// (inside_fiber); the pixels it leaves out are counted and printed.
constexpr double kRayTurn = 1e-6;
bool entries_change_when_the_ray_turns(const EmbreeCapsules& oracle, const Vec3f& org, const std::array<double, 3>& dir,
                                       const std::vector<EmbreeCapsules::Hit>& hits) {
    auto fibers = [&](const std::vector<EmbreeCapsules::Hit>& entries) {
        std::vector<unsigned> out;
        for (const auto& e : entries) out.push_back(oracle.fiber(e.segment));
        return out;
    };
    const std::vector<unsigned> here = fibers(hits);
    // Two unit vectors across the ray.
    const std::array<double, 3> helper = std::fabs(dir[0]) < 0.9 ? std::array<double, 3>{1, 0, 0} : std::array<double, 3>{0, 1, 0};
    auto cross = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
        return std::array<double, 3>{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    };
    auto unit = [](std::array<double, 3> v) {
        const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        return std::array<double, 3>{v[0] / n, v[1] / n, v[2] / n};
    };
    const auto e1 = unit(cross(dir, helper)), e2 = cross(dir, e1);
    for (const auto& e : {e1, e2})
        for (double side : {-1.0, 1.0}) {
            const auto turned = unit({dir[0] + side * kRayTurn * e[0], dir[1] + side * kRayTurn * e[1],
                                      dir[2] + side * kRayTurn * e[2]});
            if (fibers(oracle.all(org, turned)) != here) return true;
        }
    return false;
}

// The oracle's every entry along each pixel's ray composited front to back
// (colour |direction|, each entry with alpha_of(segment)) against the traced
// image: per pixel the largest channel difference /255, pixels crossing a
// voxel with more than k = 8 entries, and grazing rays
// (entries_change_when_the_ray_turns) counted apart.
struct CompositingAgreement {
    int worst = 0, grazing_worst = 0;
    std::size_t pixels = 0, within = 0, crowded = 0, crowded_within = 0, max_in_voxel = 0, grazing = 0;
    std::size_t invisible_only = 0, invisible_lit = 0;  // rays entering only alpha-0 fibers; of those, lit over 2/255
    double rate() const { return double(within) / double(pixels - grazing); }
};

CompositingAgreement compare_with_oracle_compositing(const TracedImage& img, const Camera& cam, int w, int h,
                                                     const vrt::VoxelGrid& grid, const EmbreeCapsules& oracle,
                                                     const std::function<double(unsigned)>& alpha_of) {
    CompositingAgreement r;
    r.pixels = std::size_t(w) * std::size_t(h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const auto dir = camera_pixel_ray(cam, x, y, w, h);
            const auto hits = oracle.all(cam.position, dir);
            double rgb[3] = {0, 0, 0}, transmittance = 1;
            std::map<std::array<int, 3>, std::size_t> per_voxel;
            bool any_visible = false;
            for (const auto& hit : hits) {
                const double a = alpha_of(hit.segment);
                any_visible |= a > 0;
                const auto c = oracle.direction(hit.segment);
                for (int k = 0; k < 3; ++k) rgb[k] += transmittance * a * std::fabs(c[k]);
                transmittance *= 1 - a;
                const auto g = grid.to_grid({cam.position.x + float(hit.t * dir[0]), cam.position.y + float(hit.t * dir[1]),
                                             cam.position.z + float(hit.t * dir[2])});
                r.max_in_voxel = std::max(r.max_in_voxel, ++per_voxel[{int(g[0]), int(g[1]), int(g[2])}]);
            }
            bool over_k = false;
            for (const auto& [v, count] : per_voxel) over_k |= count > 8;
            const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
            int diff = 0;
            for (int k = 0; k < 3; ++k)
                diff = std::max(diff, std::abs(int(img.rgba[4 * i + std::size_t(k)]) - int(std::lround(rgb[k] * 255))));
            if (entries_change_when_the_ray_turns(oracle, cam.position, dir, hits)) {
                ++r.grazing, r.grazing_worst = std::max(r.grazing_worst, diff);
            } else {
                r.worst = std::max(r.worst, diff);
                r.within += diff <= 2;
                r.crowded += over_k;
                r.crowded_within += over_k && diff <= 2;
            }
            if (!hits.empty() && !any_visible) {
                ++r.invisible_only;
                r.invisible_lit += std::max({img.rgba[4 * i], img.rgba[4 * i + 1], img.rgba[4 * i + 2]}) > 2;
            }
        }
    return r;
}

}  // namespace
#endif

TEST(VoxelRtTrace, OpaqueImagesAgreeWithEmbree) {
#if !FIBLET_HAS_EMBREE
    GTEST_SKIP() << "built without Embree (libembree-dev, scripts/setup.sh)";
#else
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(shared_data("bundles/CST_R-step0.1.tck"));
    const FftFile& file = compressed.file;
    const viewer::GpuScene& scene = compressed.scene;
    const float radius = 0.3f;
    const EmbreeCapsules oracle(file, radius);
    for (const char* view : {"left", "oblique"}) {
        SCOPED_TRACE(view);
        viewer::RenderOptions o;
        o.tube_radius_mm = radius;
        expect_opaque_agreement(scene, oracle, view, o, 0.01 * radius);
    }
#endif
}

TEST(VoxelRtTrace, PerFiberRadiiAgreeWithEmbree) {
#if !FIBLET_HAS_EMBREE
    GTEST_SKIP() << "built without Embree (libembree-dev, scripts/setup.sh)";
#else
    FIBLET_REQUIRE_GL();
    CompressedScene compressed(shared_data("bundles/CST_R-step0.1.tck"));
    const FftFile& file = compressed.file;
    viewer::GpuScene& scene = compressed.scene;
    // 0.1 to 0.6 mm, neighbours in file order differing.
    std::vector<float> radii(file.header().fibers);
    for (std::size_t f = 0; f < radii.size(); ++f) radii[f] = 0.1f + 0.125f * float((f * 7) % 5);
    scene.set_fiber_radii(radii);
    const EmbreeCapsules oracle(file, 0.0f, radii);
    viewer::RenderOptions o;
    o.tube_radius_mm = 0.3f;  // ignored: --fiber-radii
    o.fiber_radii = true;
    for (const char* view : {"left", "oblique"}) {
        SCOPED_TRACE(view);
        expect_opaque_agreement(scene, oracle, view, o, 0.01 * 0.1);
    }
    // The radii reach the image: the default radius alone draws another one.
    const Camera cam = viewer::camera_from_spec("oblique", scene, 1.0f, 35, 2.0f);
    o.fiber_radii = false;
    const auto uniform = trace_image(scene, cam, 120, 120, o).segments;
    o.fiber_radii = true;
    const auto per_fiber = trace_image(scene, cam, 120, 120, o).segments;
    std::size_t differ = 0;
    for (std::size_t i = 0; i < uniform.size(); ++i) differ += (uniform[i] != 0) != (per_fiber[i] != 0);
    std::printf("per-fiber radii vs --radius 0.3 alone: %zu of %zu pixels differ in hit/miss\n", differ, uniform.size());
    EXPECT_GT(differ, 200u);
#endif
}

#if FIBLET_HAS_EMBREE
namespace {
// The scene of the transparency tests: CST_R-step0.1 as 0.6 mm capsules on
// a coarse 12³ grid, so that voxels hold more than k = 8 entries of a ray,
// seen obliquely, unlit (colour = |direction|: the oracle composites the
// same colours), with the oracle of the same capsules.
struct CoarseGridCapsules {
    static constexpr int kGrid = 12;
    static constexpr float kRadius = 0.6f;
    TempDir dir;
    FftFile file{compress_into(dir, shared_data("bundles/CST_R-step0.1.tck"), "cst.fft")};
    viewer::GpuScene scene{file, *viewer_gl().programs};
    EmbreeCapsules oracle{file, kRadius};
    vrt::VoxelGrid grid = vrt::grid_around(scene.bounds(), kGrid, kRadius);
    Camera cam = viewer::camera_from_spec("oblique", scene, 1.0f, 35, 2.0f);
    viewer::RenderOptions options(float opacity) const {
        viewer::RenderOptions o;
        o.tube_radius_mm = kRadius;
        o.opacity = opacity;
        o.lighting = false;
        o.voxel_grid = kGrid;
        return o;
    }
};
}  // namespace
#endif

TEST(VoxelRtTrace, TransparencyMatchesEmbreeCompositingEveryHit) {
#if !FIBLET_HAS_EMBREE
    GTEST_SKIP() << "built without Embree (libembree-dev, scripts/setup.sh)";
#else
    FIBLET_REQUIRE_GL();
    const CoarseGridCapsules c;
    const int w = 160, h = 160;
    const float alpha = 0.25f;
    const EmbreeCapsules& oracle = c.oracle;
    const vrt::VoxelGrid& grid = c.grid;
    const Camera& cam = c.cam;
    const TracedImage img = trace_image(c.scene, cam, w, h, c.options(alpha));
    const CompositingAgreement r =
        compare_with_oracle_compositing(img, cam, w, h, grid, oracle, [&](unsigned) { return double(alpha); });
    std::printf("transparency (alpha %.2f) vs Embree, every hit composited: %.5f of %zu pixels within 2/255 (worst "
                "%d/255); %zu pixels cross a voxel with more than k = 8 hits (at most %zu), %zu of them within 2/255; "
                "%zu pixels left out, their rays within %g · t of a silhouette (worst %d/255)\n",
                alpha, r.rate(), r.pixels - r.grazing, r.worst, r.crowded, r.max_in_voxel, r.crowded_within, r.grazing,
                kRayTurn, r.grazing_worst);
    EXPECT_GT(r.crowded, 100u);
    EXPECT_EQ(r.crowded_within, r.crowded);
    EXPECT_LE(r.worst, 2);
    EXPECT_LE(r.grazing, r.pixels / 1000);  // grazing rays stay rare: kRayTurn not too large
#endif
}

// Per-fiber opacities (--fiber-opacity) times --opacity: each capsule
// entered composites with its fiber's product (the GPU's float product,
// fiber_colors.glsl), against Embree's every hit; a fiber of opacity 0 is
// not drawn at all: no pixel names one of its segments, and where only such
// fibers lie the pixel stays background (but where the two ray tracers
// disagree on a silhouette, as the image bound allows).
TEST(VoxelRtTrace, PerFiberOpacityMatchesEmbreeCompositingEveryHit) {
#if !FIBLET_HAS_EMBREE
    GTEST_SKIP() << "built without Embree (libembree-dev, scripts/setup.sh)";
#else
    FIBLET_REQUIRE_GL();
    CoarseGridCapsules c;
    const int w = 160, h = 160;
    const float global = 0.5f;
    // U(0, 1), every fourth fiber 0.
    std::mt19937 rng(1818);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    std::vector<float> alpha(c.scene.fiber_count());
    for (std::size_t f = 0; f < alpha.size(); ++f) alpha[f] = f % 4 == 0 ? 0.0f : uniform(rng);
    c.scene.set_fiber_opacities(alpha);
    const EmbreeCapsules& oracle = c.oracle;
    const vrt::VoxelGrid& grid = c.grid;
    const Camera& cam = c.cam;
    viewer::RenderOptions o = c.options(global);
    o.fiber_opacity = true;
    const TracedImage img = trace_image(c.scene, cam, w, h, o);
    const CompositingAgreement r = compare_with_oracle_compositing(
        img, cam, w, h, grid, oracle, [&](unsigned segment) { return double(global * alpha[oracle.fiber(segment)]); });
    std::size_t names_invisible = 0;
    for (const std::uint32_t s : img.segments) names_invisible += s != 0 && alpha[oracle.fiber(s - 1)] == 0;
    std::printf("per-fiber opacity (%.2f x U(0,1), every 4th fiber 0) vs Embree, every hit composited: %.5f of %zu "
                "pixels within 2/255 (worst %d/255); %zu pixels cross a voxel with more than k = 8 hits, %zu of them "
                "within 2/255; %zu pixels left out, their rays within %g · t of a silhouette (worst %d/255); %zu pixels "
                "only on fibers of opacity 0, %zu of them lit over 2/255; %zu pixels name a segment of opacity 0\n",
                double(global), r.rate(), r.pixels - r.grazing, r.worst, r.crowded, r.crowded_within, r.grazing, kRayTurn,
                r.grazing_worst, r.invisible_only, r.invisible_lit, names_invisible);
    EXPECT_GT(r.crowded, 100u);
    EXPECT_EQ(r.crowded_within, r.crowded);
    EXPECT_LE(r.worst, 2);
    EXPECT_LE(r.grazing, r.pixels / 1000);  // grazing rays stay rare: kRayTurn not too large
    EXPECT_GT(r.invisible_only, 20u);
    EXPECT_EQ(r.invisible_lit, 0u);
    EXPECT_EQ(names_invisible, 0u);
#endif
}

namespace {

// The ambient occlusion volume sampled trilinearly at a point (voxel
// units), as the trace shader's texture lookup.
float sample_volume(const std::vector<float>& v, int n, std::array<float, 3> p) {
    float out = 0;
    const float x = p[0] - 0.5f, y = p[1] - 0.5f, z = p[2] - 0.5f;
    const int x0 = int(std::floor(x)), y0 = int(std::floor(y)), z0 = int(std::floor(z));
    for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
            for (int dx = 0; dx < 2; ++dx) {
                const int xi = std::clamp(x0 + dx, 0, n - 1), yi = std::clamp(y0 + dy, 0, n - 1),
                          zi = std::clamp(z0 + dz, 0, n - 1);
                const float wx = dx ? x - float(x0) : 1 - (x - float(x0)), wy = dy ? y - float(y0) : 1 - (y - float(y0)),
                            wz = dz ? z - float(z0) : 1 - (z - float(z0));
                out += wx * wy * wz * v[std::size_t((zi * n + yi) * n + xi)];
            }
    return out;
}

// The ambient occlusion volume of capsules of radius r (voxel units) in
// the 64³ test grid.
std::vector<float> ambient_occlusion_of(const std::vector<Capsule>& capsules, float r) {
    const vrt::VoxelRtPrograms programs;
    vrt::VoxelGrid grid;
    grid.n = kGrid, grid.voxel_mm = 1, grid.origin = {0, 0, 0};
    std::vector<float> points;
    for (const Capsule& c : capsules) points.insert(points.end(), {c.a[0], c.a[1], c.a[2], 1, c.b[0], c.b[1], c.b[2], 1});
    const viewer::GlBuffer buffer = viewer::make_buffer(GLsizeiptr(points.size() * 4), points.data(), 0);
    const vrt::VoxelStructure structure(programs, grid, {buffer.get(), std::uint32_t(capsules.size()), 1, nullptr}, r,
                                        true);
    return structure.read_ambient_occlusion();
}

}  // namespace

TEST(VoxelRtAmbientOcclusion, HalfSpaceSlabIsHalfOccludedAnIsolatedLineNot) {
    FIBLET_REQUIRE_GL();
    // A slab of touching lines along x filling z < 32 (surface at z = 32).
    std::vector<Capsule> slab;
    for (float z = 0.5f; z <= 31.5f; z += 0.5f)
        for (float y = 0.5f; y <= 63.5f; y += 0.5f) slab.push_back({{0.5f, y, z}, {63.5f, y, z}});
    const auto ao = ambient_occlusion_of(slab, 0.5f);
    // On the surface, looked up half a voxel out along the normal (as the trace shader).
    const float surface = sample_volume(ao, kGrid, {32, 32, 32.5f});
    // One line of radius 0.2 voxel through the middle.
    const auto line_ao = ambient_occlusion_of({{{4.5f, 30.3f, 31.7f}, {59.5f, 33.1f, 32.2f}}}, 0.2f);
    const float line = sample_volume(line_ao, kGrid, {32, 31.6f + 0.7f, 31.95f});
    std::printf("ambient occlusion: half-space slab surface %.4f, isolated line %.4f\n", surface, line);
    EXPECT_NEAR(surface, 0.5f, 0.05f);
    EXPECT_LT(line, 0.05f);
}

TEST(VoxelRtAmbientOcclusion, CorrelatesWithMonteCarloOcclusionRays) {
#if !FIBLET_HAS_EMBREE
    GTEST_SKIP() << "built without Embree (libembree-dev, scripts/setup.sh)";
#else
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(shared_data("bundles/CST_R-step0.1.tck"));
    const FftFile& file = compressed.file;
    const viewer::GpuScene& scene = compressed.scene;
    const float radius = 0.3f;
    const EmbreeCapsules oracle(file, radius);
    viewer::Renderer renderer(*viewer_gl().programs);
    viewer::RenderOptions o;
    o.engine = viewer::RenderEngine::voxel_rt;
    o.voxel_grid = 64, o.tube_radius_mm = radius, o.ambient_occlusion = true;
    const Camera cam = viewer::camera_from_spec("oblique", scene, 1.0f, 35, 2.0f);
    viewer::RenderTarget target(8, 8);
    renderer.render(scene, cam, o, target);
    const vrt::VoxelStructure& structure = *renderer.voxel_ray_tracer().structure();
    const auto ao = structure.read_ambient_occlusion();
    const vrt::VoxelGrid& grid = structure.grid();
    // Surface points: Embree's hits of a coarse image; per point, the cone
    // estimate against the fraction of 256 uniform directions blocked
    // between the cones' start and reach (1 and 16 voxels,
    // cone_occlusion.glsl), both from the lookup point half a voxel out
    // along the normal.
    std::mt19937 rng(3);
    std::normal_distribution<double> g;
    const float reach = 16 * grid.voxel_mm;
    std::vector<double> cones, rays;
    const int w = 48, h = 48;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const auto dir = camera_pixel_ray(cam, x, y, w, h);
            const auto hit = oracle.nearest(cam.position, dir);
            if (!std::isfinite(hit.t)) continue;
            const Vec3f p{cam.position.x + float(hit.t * dir[0]), cam.position.y + float(hit.t * dir[1]),
                          cam.position.z + float(hit.t * dir[2])};
            const auto [a, b] = oracle.ends(hit.segment);
            const float abx = b.x - a.x, aby = b.y - a.y, abz = b.z - a.z;
            const float u = std::clamp(((p.x - a.x) * abx + (p.y - a.y) * aby + (p.z - a.z) * abz) /
                                           std::max(abx * abx + aby * aby + abz * abz, 1e-12f), 0.0f, 1.0f);
            float nx = p.x - (a.x + u * abx), ny = p.y - (a.y + u * aby), nz = p.z - (a.z + u * abz);
            const float nn = std::sqrt(nx * nx + ny * ny + nz * nz);
            nx /= nn, ny /= nn, nz /= nn;
            auto gp = grid.to_grid({p.x, p.y, p.z});
            cones.push_back(sample_volume(ao, grid.n, {gp[0] + 0.5f * nx, gp[1] + 0.5f * ny, gp[2] + 0.5f * nz}));
            const float out = 0.5f * grid.voxel_mm;
            const Vec3f start{p.x + out * nx, p.y + out * ny, p.z + out * nz};
            int blocked = 0;
            for (int k = 0; k < 256; ++k) {
                double v[3] = {g(rng), g(rng), g(rng)};
                const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
                blocked += oracle.occluded(start, {v[0] / n, v[1] / n, v[2] / n}, grid.voxel_mm, reach);
            }
            rays.push_back(blocked / 256.0);
        }
    const double n = double(cones.size());
    double mc = 0, mr = 0;
    for (std::size_t i = 0; i < cones.size(); ++i) mc += cones[i] / n, mr += rays[i] / n;
    double scc = 0, srr = 0, scr = 0;
    for (std::size_t i = 0; i < cones.size(); ++i)
        scc += (cones[i] - mc) * (cones[i] - mc), srr += (rays[i] - mr) * (rays[i] - mr),
            scr += (cones[i] - mc) * (rays[i] - mr);
    const double correlation = scr / std::sqrt(scc * srr);
    std::printf("ambient occlusion at %zu surface points: cones mean %.3f, Monte-Carlo rays mean %.3f, "
                "correlation %.4f\n",
                cones.size(), mc, mr, correlation);
    EXPECT_GT(cones.size(), 200u);
    EXPECT_GE(correlation, 0.9);
#endif
}

TEST(VoxelRtAmbientOcclusion, OneChordPerBlockMatchesEverySegment) {
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(shared_data("small-ifod1.tck"));
    const viewer::GpuScene& scene = compressed.scene;
    viewer::Renderer renderer(*viewer_gl().programs);
    viewer::RenderOptions o;
    o.engine = viewer::RenderEngine::voxel_rt;
    o.ambient_occlusion = true;
    // 64³ in CI; FIBLET_VOXEL_RT_GRID=128 for the figure.
    o.voxel_grid = std::getenv("FIBLET_VOXEL_RT_GRID") ? std::atoi(std::getenv("FIBLET_VOXEL_RT_GRID")) : 64;
    const Camera cam = viewer::camera_from_spec("oblique", scene, 1.0f, 35, 2.0f);
    viewer::RenderTarget target(8, 8);
    renderer.render(scene, cam, o, target);
    auto& tracer = renderer.voxel_ray_tracer();
    const auto full = tracer.structure()->read_ambient_occlusion();
    const auto cells = tracer.structure()->read_cells();
    tracer.chord_occlusion(scene, o);
    const auto chords = tracer.chord_occlusion_structure()->structure().read_ambient_occlusion();
    ASSERT_EQ(full.size(), chords.size());
    // Over the voxels the fibers occupy (where surfaces are shaded).
    std::vector<double> diff;
    double mf = 0, mc = 0;
    std::vector<std::size_t> used;
    for (std::size_t v = 0; v < full.size(); ++v)
        if (cells[v] & 0xffffu) used.push_back(v), mf += full[v], mc += chords[v];
    const double n = double(used.size());
    mf /= n, mc /= n;
    double sff = 0, scc = 0, sfc = 0, mean_abs = 0;
    for (std::size_t v : used) {
        const double f = full[v] - mf, c = chords[v] - mc;
        sff += f * f, scc += c * c, sfc += f * c;
        diff.push_back(std::fabs(double(full[v]) - double(chords[v])));
        mean_abs += diff.back() / n;
    }
    std::sort(diff.begin(), diff.end());
    const double p99 = diff[std::size_t(0.99 * double(diff.size() - 1))];
    const double correlation = sfc / std::sqrt(sff * scc);
    std::printf("small-ifod1, %d³: chord vs full-segment ambient occlusion over %zu occupied voxels: |dAO| mean %.4f, "
                "p99 %.4f, correlation %.4f (means %.3f / %.3f)\n",
                o.voxel_grid, used.size(), mean_abs, p99, correlation, mf, mc);
    EXPECT_LE(mean_abs, 0.02);
    EXPECT_LE(p99, 0.08);
    EXPECT_GE(correlation, 0.98);
}

TEST(VoxelRtCulling, ImagesWithAndWithoutCullingAgree) {
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(shared_data("small-ifod1.tck"));
    const viewer::GpuScene& scene = compressed.scene;
    const int w = 256, h = 192;
    for (const char* view : {"oblique", "top"}) {
        SCOPED_TRACE(view);
        const Camera cam = viewer::camera_from_spec(view, scene, float(w) / float(h), 35, 1.0f);
        viewer::Renderer renderer(*viewer_gl().programs);
        renderer.voxel_ray_tracer().write_segment_ids(true);
        viewer::RenderTarget target(w, h);
        viewer::RenderOptions o;
        o.engine = viewer::RenderEngine::voxel_rt;
        o.voxel_grid = 64;
        o.frustum_culling = false;
        renderer.render(scene, cam, o, target);
        const auto off = target.read_fibers();
        o.frustum_culling = true;
        renderer.render(scene, cam, o, target);
        const auto on = target.read_fibers();
        const auto& tracer = renderer.voxel_ray_tracer();
        const std::uint64_t visible = tracer.culling()->visible_voxels();
        std::uint64_t occupied = 0;
        for (auto c : tracer.structure()->read_cells()) occupied += (c & 0xffffu) != 0;
        std::size_t same = 0;
        for (std::size_t i = 0; i < on.size(); ++i) same += on[i] == off[i];
        const double rate = double(same) / double(on.size());
        std::printf("%s: culling keeps %llu of %llu occupied voxels (%.1f %%; %.1f ms); images agree on %.5f of "
                    "pixels (same segment)\n",
                    view, static_cast<unsigned long long>(visible), static_cast<unsigned long long>(occupied),
                    100.0 * double(visible) / double(occupied), tracer.culling()->last_update_ms(), rate);
        EXPECT_LT(visible, occupied);
        EXPECT_GE(rate, 0.999);
    }
}

// The occupancy pyramid of empty-space skipping against the cells read
// back: a cell of level l >= 1 is marked exactly when a voxel under it has a
// fragment list; the pyramid stops at an odd side (12 -> 6 -> 3).
TEST(VoxelRtSkipping, OccupancyPyramidMarksExactlyTheCellsHoldingSomething) {
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(shared_data("small-ifod1.tck"));
    const viewer::GpuScene& scene = compressed.scene;
    for (const int n : {64, 12}) {
        SCOPED_TRACE(n);
        viewer::Renderer renderer(*viewer_gl().programs);
        viewer::RenderTarget target(8, 8);
        viewer::RenderOptions o;
        o.engine = viewer::RenderEngine::voxel_rt;
        o.voxel_grid = n;
        renderer.render(scene, viewer::camera_from_spec("oblique", scene, 1.0f, 35, 1.0f), o, target);
        const vrt::VoxelStructure& s = *renderer.voxel_ray_tracer().structure();
        const std::vector<std::uint32_t> offset = s.pyramid().level_offset;
        ASSERT_EQ(offset.size(), n == 64 ? 7u : 3u);
        std::vector<std::uint8_t> level(std::size_t(n) * std::size_t(n) * std::size_t(n));
        const auto cells = s.read_cells();
        for (std::size_t i = 0; i < level.size(); ++i) level[i] = (cells[i] & 0xffffu) != 0;
        const std::vector<std::uint8_t> gpu = s.read_occupied_pyramid();
        ASSERT_EQ(gpu.size(), s.pyramid().cells - offset[1]);
        std::string report;
        for (std::size_t l = 1; l < offset.size(); ++l) {
            const int side = n >> l, child = 2 * side;
            std::vector<std::uint8_t> next(std::size_t(side) * std::size_t(side) * std::size_t(side));
            for (int z = 0; z < child; ++z)
                for (int y = 0; y < child; ++y)
                    for (int x = 0; x < child; ++x)
                        next[std::size_t(((z / 2) * side + y / 2) * side + x / 2)] |=
                            level[std::size_t((z * child + y) * child + x)];
            std::size_t wrong = 0, empty = 0;
            for (std::size_t i = 0; i < next.size(); ++i) {
                wrong += gpu[offset[l] - offset[1] + i] != next[i];
                empty += !next[i];
            }
            EXPECT_EQ(wrong, 0u) << "level " << l;
            report += fmt::format(" level {} ({}³) {:.1f} %", l, side, 100.0 * double(empty) / double(next.size()));
            level = std::move(next);
        }
        std::printf("%d³ grid, empty cells:%s\n", n, report.c_str());
    }
}

// Hierarchical empty-space skipping only leaves out empty cells: the images
// with it and without it (the DDA voxel by voxel) are the same, for opaque
// primary rays through the culling's visibility pyramid, for shadow rays and
// primary rays without culling through the occupancy pyramid, and for
// transparent rays.
TEST(VoxelRtSkipping, ImagesWithAndWithoutEmptySpaceSkippingAreTheSame) {
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(shared_data("small-ifod1.tck"));
    const viewer::GpuScene& scene = compressed.scene;
    struct Case {
        const char* name;
        float opacity;
        bool culling, shading;
        int w, h;
    };
    // Transparent frames on llvmpipe take seconds: a smaller image.
    const Case cases[] = {{"opaque, culling", 1.0f, true, false, 256, 192},
                          {"opaque, no culling, --ao --shadows", 1.0f, false, true, 256, 192},
                          {"opacity 0.3", 0.3f, false, false, 96, 72}};
    for (const Case& c : cases)
        for (const char* view : {"oblique", "top"}) {
            SCOPED_TRACE(std::string(c.name) + ", " + view);
            const Camera cam = viewer::camera_from_spec(view, scene, float(c.w) / float(c.h), 35, 1.0f);
            viewer::Renderer renderer(*viewer_gl().programs);
            renderer.voxel_ray_tracer().write_segment_ids(true);
            viewer::RenderTarget target(c.w, c.h);
            viewer::RenderOptions o;
            o.engine = viewer::RenderEngine::voxel_rt;
            o.voxel_grid = 64;
            o.opacity = c.opacity;
            o.frustum_culling = c.culling;
            o.ambient_occlusion = o.shadows = c.shading;
            o.time_stages = true;
            renderer.render(scene, cam, o, target);  // builds the structure
            o.empty_space_skipping = false;
            const double off_ms = renderer.render(scene, cam, o, target).draw_ms;
            const auto off_fibers = target.read_fibers();
            const auto off_rgba = target.read_rgba();
            o.empty_space_skipping = true;
            const double on_ms = renderer.render(scene, cam, o, target).draw_ms;
            const auto on_fibers = target.read_fibers();
            const auto on_rgba = target.read_rgba();
            std::size_t same = 0, hit = 0;
            for (std::size_t i = 0; i < on_fibers.size(); ++i) {
                bool eq = on_fibers[i] == off_fibers[i];
                for (std::size_t k = 0; k < 4; ++k) eq &= on_rgba[4 * i + k] == off_rgba[4 * i + k];
                same += eq;
                hit += off_fibers[i] != 0;
            }
            const double rate = double(same) / double(on_fibers.size());
            std::printf("%s, %s: with and without empty-space skipping %.5f of %zu pixels identical (%zu hit); trace "
                        "%.1f ms vs %.1f ms without\n",
                        c.name, view, rate, on_fibers.size(), hit, on_ms, off_ms);
            EXPECT_GT(hit, std::size_t(c.w * c.h / 10));
            EXPECT_GE(rate, 0.999);
        }
}

TEST(VoxelRtCli, RenderDrawsWithEveryOptionAndRefusesBadOnes) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string fft = compress_into(dir, shared_data("bundles/CST_R-step0.1.tck"), "cst.fft");
    {
        const FftFile file(fft);
        std::FILE* f = std::fopen(dir.file("radii.txt").c_str(), "w");
        for (std::uint64_t k = 0; k < file.header().fibers; ++k) std::fprintf(f, "%g\n", 0.2 + 0.1 * double(k % 3));
        std::fclose(f);
    }
    const std::string radii = "--engine voxel-rt --grid 32 --ao --fiber-radii " + dir.file("radii.txt");
    const char* cases[] = {"--engine voxel-rt --grid 32", "--engine voxel-rt --grid 32 --ao --shadows",
                           "--engine voxel-rt --grid 32 --opacity 0.3", "--ao --style tubes --grid 32", radii.c_str()};
    for (int i = 0; i < 5; ++i) {
        const std::string png = dir.file(std::to_string(i) + ".png");
        const CommandResult r = run_cli("render " + fft + " -o " + png + " --size 120x90 --camera left --radius 0.4 " + cases[i]);
        ASSERT_EQ(r.status, 0) << cases[i] << ": " << r.output;
        const viewer::RgbaImage img = viewer::read_png(png);
        std::size_t lit = 0;
        for (std::size_t k = 0; k < img.rgba.size(); k += 4) lit += img.rgba[k] + img.rgba[k + 1] + img.rgba[k + 2] > 30;
        EXPECT_GT(lit, 500u) << cases[i];
    }
    for (const char* bad : {"--engine nope", "--engine voxel-rt --grid 2", "--engine voxel-rt --opacity 0",
                            "--engine voxel-rt --opacity 1.5", "--shadows",
                            "--opacity 0.5 --style tubes --transparency voxlines"}) {  // --opacity: both engines
        const CommandResult r = run_cli("render " + fft + " -o " + dir.file("x.png") + " --size 32x32 " + bad);
        EXPECT_EQ(r.status, 2) << bad << ": " << r.output;
    }
}

TEST(VoxelRtMemory, SegmentsSplitOverSeveralBuffersRenderTheSameImage) {
    FIBLET_REQUIRE_GL();
    const CompressedScene compressed(shared_data("small-ifod1.tck"));
    const viewer::GpuScene& scene = compressed.scene;
    const std::uint64_t slot_bytes = std::uint64_t(scene.header().points_per_block + 1) * 16;
    const std::uint64_t total = slot_bytes * scene.block_count();
    struct Frame {
        std::vector<std::uint32_t> fibers;
        std::vector<std::uint8_t> rgba;
        std::size_t parts, fragment_parts;
        std::uint64_t fragments;
        double decode_ms, draw_ms;
    };
    // The trace's time: the best of two frames after the one that builds.
    auto draw = [&](std::uint64_t part_bytes, const viewer::RenderOptions& o, int w, int h) {
        const Camera cam = viewer::camera_from_spec("oblique", scene, float(w) / float(h), 35, 1.0f);
        viewer::Renderer renderer(*viewer_gl().programs);
        renderer.voxel_ray_tracer().write_segment_ids(true);
        renderer.voxel_ray_tracer().set_segment_part_bytes(part_bytes);
        viewer::RenderTarget target(w, h);
        renderer.render(scene, cam, o, target);
        double best = 1e30;
        for (int k = 0; k < 2; ++k) best = std::min(best, renderer.render(scene, cam, o, target).draw_ms);
        const auto& tracer = renderer.voxel_ray_tracer();
        return Frame{target.read_fibers(), target.read_rgba(), tracer.segment_parts(), tracer.fragment_parts(),
                     tracer.structure()->fragment_count(), tracer.last_decode_ms(), best};
    };
    // Five parts (the last one partly filled).
    const std::uint64_t part_bytes = total / 5 + slot_bytes;
    for (const float opacity : {1.0f, 0.3f}) {
        SCOPED_TRACE(opacity);
        viewer::RenderOptions o;
        o.engine = viewer::RenderEngine::voxel_rt;
        o.voxel_grid = 64;
        o.ambient_occlusion = opacity >= 1, o.shadows = opacity >= 1;
        o.opacity = opacity;
        o.time_stages = true;
        // Transparent frames on llvmpipe take seconds: a smaller image.
        const int w = opacity < 1 ? 96 : 256, h = opacity < 1 ? 72 : 192;
        const Frame one = draw(0, o, w, h), split = draw(part_bytes, o, w, h);
        ASSERT_EQ(one.parts, 1u);
        ASSERT_EQ(one.fragment_parts, 1u);
        ASSERT_EQ(split.parts, 5u);
        ASSERT_GE(split.fragment_parts, 2u);
        std::size_t same = 0, hit = 0;
        for (std::size_t i = 0; i < one.fibers.size(); ++i) {
            bool eq = one.fibers[i] == split.fibers[i];
            for (int k = 0; k < 4; ++k) eq &= one.rgba[4 * i + std::size_t(k)] == split.rgba[4 * i + std::size_t(k)];
            same += eq;
            hit += one.fibers[i] != 0;
        }
        const double rate = double(same) / double(one.fibers.size());
        std::printf("opacity %.1f: %.2f MiB of segments and %.2f MiB of fragment lists in one buffer each vs %zu and "
                    "%zu buffers of %.2f MiB: %.5f of %zu pixels identical (%zu hit); decode %.1f / %.1f ms, trace "
                    "%.1f / %.1f ms\n",
                    double(opacity), double(total) / 1048576.0, double(one.fragments) * 4 / 1048576.0, split.parts,
                    split.fragment_parts, double(part_bytes) / 1048576.0, rate, one.fibers.size(), hit, one.decode_ms,
                    split.decode_ms, one.draw_ms, split.draw_ms);
        EXPECT_GT(hit, std::size_t(w * h / 5));
        EXPECT_GE(rate, 0.999);
    }
    // More parts than binding points: refused, not drawn in part.
    viewer::Renderer renderer(*viewer_gl().programs);
    renderer.voxel_ray_tracer().set_segment_part_bytes(total / 9);
    viewer::RenderTarget target(8, 8);
    viewer::RenderOptions o;
    o.engine = viewer::RenderEngine::voxel_rt;
    o.voxel_grid = 16;
    EXPECT_THROW(renderer.render(scene, viewer::camera_from_spec("oblique", scene, 1.0f, 35, 1.0f), o, target), Error);
}
