// ODF glyphs (overlays/odf_glyphs, overlays/sh_basis) and background image
// slices (overlays/image_slice) on the phantom FOD image the shared
// tractograms were tracked from (made in the build tree by the phantom_fod
// CTest fixture). The GPU's SH evaluation against MRtrix3's sh2amp and a
// plain CPU evaluation; single glyphs at lmax 4 and 8 against the same
// root finding in double on the CPU; the bounding boxes; the glyphs'
// registration with the decoded fibers; slice pixels against voxels.
// Figures: docs/viewer.md, "ODF glyphs".
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <random>

#include "fiblet/image.hpp"
#include "gl/gpu_bindings.hpp"
#include "overlays/image_slice/image_slice_overlay.hpp"
#include "overlays/odf_glyphs/glyph_ray.hpp"
#include "overlays/odf_glyphs/glyph_set.hpp"
#include "overlays/odf_glyphs/odf_glyphs_overlay.hpp"
#include "overlays/sh_basis/sh_basis.hpp"
#include "cli_runner.hpp"
#include "image_source.hpp"
#include "gl/png_file.hpp"
#include "render/render_target.hpp"
#include "render/renderer.hpp"
#include "gl/shader_program.hpp"
#include "viewer_test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;

namespace {

using V3 = viewer::Vec3<double>;

std::string phantom_file(const std::string& name) { return std::string(FIBLET_PHANTOM_FOD_DIR) + "/" + name; }

#define FIBLET_REQUIRE_PHANTOM_FOD()                                                                       \
    do {                                                                                                   \
        if (!std::filesystem::exists(phantom_file("phantom-fod-crop.nii")))                               \
            GTEST_SKIP() << "no phantom FOD image (the phantom_fod CTest fixture makes it): " << FIBLET_PHANTOM_FOD_DIR; \
    } while (0)

const Image& phantom_fod() {
    static const Image image = read_image(phantom_file("phantom-fod.nii"));
    return image;
}

std::vector<float> voxel_coefficients(const Image& image, std::int64_t i, std::int64_t j, std::int64_t k) {
    std::vector<float> c(std::size_t(image.volumes()));
    for (std::size_t v = 0; v < c.size(); ++v) c[v] = image.at(i, j, k, std::int64_t(v));
    return c;
}

// Near-uniform unit directions over the whole sphere.
std::vector<V3> fibonacci_sphere(int n) {
    std::vector<V3> dirs;
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double z = 1 - 2 * (i + 0.5) / n, r = std::sqrt(1 - z * z), phi = golden * i;
        dirs.push_back({r * std::cos(phi), r * std::sin(phi), z});
    }
    return dirs;
}

// The basis as its definition reads: std::assoc_legendre (which has no
// Condon–Shortley phase, so (−1)^m is added), factorials and trigonometry.
double plain_sh_value(const std::vector<float>& c, int lmax, const V3& u) {
    const double theta = std::acos(std::clamp(u[2], -1.0, 1.0)), phi = std::atan2(u[1], u[0]);
    double sum = 0;
    for (int l = 0; l <= lmax; l += 2)
        for (int m = -l; m <= l; ++m) {
            const int am = std::abs(m);
            const double n = std::sqrt((2 * l + 1) / (4 * M_PI) * std::tgamma(l - am + 1) / std::tgamma(l + am + 1));
            const double p = (am % 2 ? -1.0 : 1.0) * n * std::assoc_legendre(unsigned(l), unsigned(am), std::cos(theta));
            const double y = m == 0 ? p : m > 0 ? std::sqrt(2.0) * p * std::cos(am * phi) : std::sqrt(2.0) * p * std::sin(am * phi);
            sum += double(c[std::size_t(viewer::sh_index(l, m))]) * y;
        }
    return sum;
}

// The GLSL evaluation (sh_values.comp.glsl, the glyphs' sh_basis.glsl).
std::vector<double> gpu_sh_values(const std::vector<float>& c, int lmax, const std::vector<V3>& dirs) {
    const viewer::GlProgram program = viewer::build_program({"sh_values.comp.glsl"}, viewer::gpu_binding_defines());
    std::vector<float> xyzw;
    for (const auto& d : dirs) xyzw.insert(xyzw.end(), {float(d[0]), float(d[1]), float(d[2]), 0.0f});
    const viewer::GlBuffer coefficients = viewer::make_buffer(GLsizeiptr(c.size() * 4), c.data(), 0);
    const viewer::GlBuffer directions = viewer::make_buffer(GLsizeiptr(xyzw.size() * 4), xyzw.data(), 0);
    glUseProgram(program.get());
    glProgramUniform1i(program.get(), viewer::uniform(program, "uLmax"), lmax);
    glProgramUniform1ui(program.get(), viewer::uniform(program, "uCount"), GLuint(dirs.size()));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, viewer::binding::kGlyphCoefficients, coefficients.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, viewer::binding::kGlyphCenters, directions.get());
    glDispatchCompute(GLuint((dirs.size() + 63) / 64), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(directions.get(), 0, GLsizeiptr(xyzw.size() * 4), xyzw.data());
    std::vector<double> out;
    for (std::size_t i = 0; i < dirs.size(); ++i) out.push_back(xyzw[4 * i + 3]);
    return out;
}

// The GLSL gradient on the sphere (sh_gradients.comp.glsl, the glyphs'
// shValueAndGradient): per direction (∇_S f, f).
std::vector<std::array<double, 4>> gpu_sh_gradients(const std::vector<float>& c, int lmax, const std::vector<V3>& dirs) {
    const viewer::GlProgram program = viewer::build_program({"sh_gradients.comp.glsl"}, viewer::gpu_binding_defines());
    std::vector<float> entries;
    for (const auto& d : dirs) entries.insert(entries.end(), {float(d[0]), float(d[1]), float(d[2]), 0.0f, 0.0f, 0.0f, 0.0f, 0.0f});
    const viewer::GlBuffer coefficients = viewer::make_buffer(GLsizeiptr(c.size() * 4), c.data(), 0);
    const viewer::GlBuffer buffer = viewer::make_buffer(GLsizeiptr(entries.size() * 4), entries.data(), 0);
    glUseProgram(program.get());
    glProgramUniform1i(program.get(), viewer::uniform(program, "uLmax"), lmax);
    glProgramUniform1ui(program.get(), viewer::uniform(program, "uCount"), GLuint(dirs.size()));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, viewer::binding::kGlyphCoefficients, coefficients.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, viewer::binding::kGlyphCenters, buffer.get());
    glDispatchCompute(GLuint((dirs.size() + 63) / 64), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(buffer.get(), 0, GLsizeiptr(entries.size() * 4), entries.data());
    std::vector<std::array<double, 4>> out;
    for (std::size_t i = 0; i < dirs.size(); ++i)
        out.push_back({entries[8 * i + 4], entries[8 * i + 5], entries[8 * i + 6], entries[8 * i + 7]});
    return out;
}

// A scene whose one fiber lies far outside every test camera's view, so
// that frames hold only the overlays.
struct EmptyScene {
    TempDir dir;
    std::unique_ptr<FftFile> file;
    std::unique_ptr<viewer::GpuScene> scene;
    EmptyScene() {
        write_tck(dir.file("far.tck"), {{{5000, 5000, 5000}, {5000.5f, 5000, 5000}, {5001, 5000, 5000}}});
        file = std::make_unique<FftFile>(compress_into(dir, dir.file("far.tck"), "far.fft"));
        scene = std::make_unique<viewer::GpuScene>(*file, *viewer_gl().programs);
    }
};

struct OverlayFrame {
    std::vector<float> depth;
    std::vector<std::uint8_t> rgba;
};
OverlayFrame render_overlays(const std::vector<std::shared_ptr<viewer::Overlay>>& overlays, const Camera& cam, int w, int h,
                             bool color_by_normal = false) {
    static EmptyScene empty;
    viewer::Renderer renderer(*viewer_gl().programs);
    renderer.set_overlays(overlays);
    viewer::RenderTarget target(w, h);
    viewer::RenderOptions o;
    o.color_by_normal = color_by_normal;
    renderer.render(*empty.scene, cam, o, target);
    return {target.read_depth(), target.read_rgba()};
}

struct Ray {
    V3 origin, dir;
};
V3 v3(Vec3f v) { return {v.x, v.y, v.z}; }
V3 sub(V3 a, V3 b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V3 add(V3 a, V3 b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
V3 mul(double s, V3 a) { return {s * a[0], s * a[1], s * a[2]}; }
double norm(V3 a) { return std::sqrt(viewer::dot3(a, a)); }
V3 unit(V3 a) { return mul(1 / norm(a), a); }
V3 cross(V3 a, V3 b) { return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; }

// The ray through the centre of pixel (x, y), y from the top.
Ray pixel_ray(const Camera& c, int w, int h, int x, int y) {
    const V3 fwd = unit(sub(v3(c.target), v3(c.position)));
    const V3 right = unit(cross(fwd, v3(c.up))), up = cross(right, fwd);
    const double t = std::tan(c.fov_y_deg * M_PI / 360);
    const double sx = ((x + 0.5) / w * 2 - 1) * t * c.aspect, sy = (1 - (y + 0.5) / h * 2) * t;
    return {v3(c.position), unit(add(fwd, add(mul(sx, right), mul(sy, up))))};
}

// Distance along the ray of pixel (x, y) from its window depth.
double depth_to_distance(const Camera& c, float depth, const Ray& ray) {
    const double n = c.near_mm, f = c.far_mm, z_ndc = 2.0 * depth - 1.0;
    const double z_eye = 2 * n * f / ((f + n) - z_ndc * (f - n));
    return z_eye / viewer::dot3(ray.dir, unit(sub(v3(c.target), v3(c.position))));
}

// The phantom voxel of the middle axial slice with the most lobes (a
// crossing), found by sampling: its coefficients.
std::vector<float> crossing_voxel(const Image& fod) {
    const auto dirs = fibonacci_sphere(600);
    int best_lobes = -1;
    std::vector<float> best;
    for (std::int64_t j = 20; j < 80; j += 3)
        for (std::int64_t i = 20; i < 80; i += 3) {
            const auto c = voxel_coefficients(fod, i, j, 50);
            std::vector<double> v;
            for (const auto& d : dirs) v.push_back(viewer::sh_value<double>(c, 8, d[0], d[1], d[2]));
            const double peak = *std::max_element(v.begin(), v.end());
            if (!(peak > 0)) continue;
            // Local maxima above 30 % of the peak, among neighbours within 15°; each lobe counted twice (±u).
            int lobes = 0;
            for (std::size_t a = 0; a < dirs.size(); ++a) {
                if (v[a] < 0.3 * peak) continue;
                bool top = true;
                for (std::size_t b = 0; b < dirs.size() && top; ++b)
                    top = !(b != a && viewer::dot3(dirs[a], dirs[b]) > std::cos(15 * M_PI / 180) && v[b] > v[a]);
                lobes += top;
            }
            if (lobes > best_lobes) best_lobes = lobes, best = c;
        }
    return best;
}

struct GlyphAgreement {
    int pixels = 0, agree = 0, both = 0;
    double p99_dt = 0, max_dt = 0, max_radius_error = 0, max_box_excess = 0;
    double p99_normal_deg = 0;   // GPU normal (8-bit colour) vs the CPU's (the same closed form in double)
    double p99_cpu_normal_deg = 0;  // the CPU's closed-form normal vs a central difference of F in double
    // Every 4th pixel on both axes against a march along the ray (no
    // polynomial, no root finder): hit/miss agreement of the CPU reference
    // and of the GPU with it, and the largest |t - t_march| where all hit.
    int marched = 0, march_agree_cpu = 0, march_agree_gpu = 0;
    double max_march_dt = 0;
};

// The first t in [t_min, t_min + span] where the ray o + t d enters the
// glyph {x : |x| <= |f(x / |x|)|}, sampled every span / steps: an
// independent reference for the root finder.
std::optional<double> march_glyph(const std::vector<double>& c, int lmax, const V3& o, const V3& d, double t_min,
                                  double span, int steps) {
    for (int i = 0; i <= steps; ++i) {
        const double t = t_min + span * i / steps;
        const V3 x = add(o, mul(t, d));
        const double r = norm(x);
        if (r == 0) continue;
        if (r <= std::abs(viewer::sh_value<double>(c, lmax, x[0] / r, x[1] / r, x[2] / r))) return t;
    }
    return std::nullopt;
}

// F(x) = f_h(x)² − ‖x‖^{2k+2} (glyph_ray.hpp), for a normal by differences.
template <class Coefficients>
double glyph_function(const Coefficients& c, int k, const V3& x) {
    const double h = viewer::homogenized<double>(c, k, x);
    return h * h - std::pow(viewer::dot3(x, x), k + 1);
}

// One glyph of `coefficients` truncated to `lmax` at the origin (radius 1
// mm: glyph units are mm) drawn at 256² from an oblique camera, against
// trace_glyph<double> per pixel. At the default field of view the glyph's
// middle fills the image; at 40° its whole outline is in view.
GlyphAgreement compare_single_glyph(const std::vector<float>& coefficients, int lmax, float fov_y_deg = 18) {
    viewer::GlyphSet set;
    set.lmax = lmax;
    set.coefficients_per_glyph = viewer::sh_coefficient_count(lmax);
    const double bound = viewer::sh_amplitude_bound(coefficients.data(), lmax);
    for (int i = 0; i < set.coefficients_per_glyph; ++i) set.coefficients.push_back(float(coefficients[std::size_t(i)] / bound));
    set.centers.push_back({0, 0, 0, 1});
    set.extents.push_back(viewer::glyph_box_extents(set.coefficients, lmax, viewer::fibonacci_half_sphere(512)));
    const auto box = set.extents[0];
    const auto overlay = std::make_shared<viewer::OdfGlyphsOverlay>(set);
    Camera cam;
    cam.position = {2.2f, -2.9f, 1.7f};
    cam.target = {0, 0, 0};
    cam.up = {0, 0, 1};
    cam.fov_y_deg = fov_y_deg;
    cam.aspect = 1;
    cam.near_mm = 2, cam.far_mm = 6;
    const int w = 256, h = 256;
    const OverlayFrame frame = render_overlays({overlay}, cam, w, h);
    const OverlayFrame normals = render_overlays({overlay}, cam, w, h, true);
    std::vector<double> ref_coefficients(set.coefficients.begin(), set.coefficients.end());
    // The CPU gets the float coefficients the GPU has.
    const auto minv = viewer::glyph_inverse_vandermonde(lmax);
    GlyphAgreement a;
    std::vector<double> dts, normal_deg, cpu_normal_deg;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Ray ray = pixel_ray(cam, w, h, x, y);
            const double along = -viewer::dot3(ray.origin, ray.dir);  // to the point nearest the centre
            const V3 o = add(ray.origin, mul(along, ray.dir));
            const auto ref = viewer::trace_glyph<double>(ref_coefficients, lmax, minv, o, ray.dir, -along, 1e-12);
            const float depth = frame.depth[std::size_t(y * w + x)];
            const bool gpu = depth < 1.0f;
            if (x % 4 == 0 && y % 4 == 0) {
                // The whole chord of a sphere of radius 1.25 around the centre.
                const auto march = march_glyph(ref_coefficients, lmax, o, ray.dir, -1.25, 2.5, 2500);
                ++a.marched;
                a.march_agree_cpu += bool(march) == bool(ref);
                a.march_agree_gpu += bool(march) == gpu;
                if (march && ref && gpu)
                    a.max_march_dt = std::max(a.max_march_dt, std::abs(*march - ref->t));
            }
            ++a.pixels;
            a.agree += gpu == bool(ref);
            if (!gpu) continue;
            const double t = depth_to_distance(cam, depth, ray);
            const V3 p = add(ray.origin, mul(t, ray.dir));
            const V3 u = unit(p);
            a.max_radius_error = std::max(a.max_radius_error,
                                          std::abs(norm(p) - std::abs(viewer::sh_value<double>(ref_coefficients, lmax, u[0], u[1], u[2]))));
            a.max_box_excess = std::max({a.max_box_excess, std::abs(p[0]) - box[0], std::abs(p[1]) - box[1], std::abs(p[2]) - box[2]});
            if (!ref) continue;
            ++a.both;
            dts.push_back(std::abs(t - (along + ref->t)));
            const std::size_t i = std::size_t(4 * (y * w + x));
            const V3 gpu_normal = unit({normals.rgba[i] / 127.5 - 1, normals.rgba[i + 1] / 127.5 - 1, normals.rgba[i + 2] / 127.5 - 1});
            const auto angle = [](const V3& u, const V3& v) {
                return std::atan2(norm(cross(u, v)), viewer::dot3(u, v)) * 180 / M_PI;
            };
            normal_deg.push_back(angle(gpu_normal, ref->normal));
            const V3 q = add(o, mul(ref->t, ray.dir));
            V3 gradient;
            for (int axis = 0; axis < 3; ++axis) {
                V3 e{0, 0, 0};
                e[std::size_t(axis)] = 1e-6;
                gradient[std::size_t(axis)] = glyph_function(ref_coefficients, lmax, sub(q, e)) - glyph_function(ref_coefficients, lmax, add(q, e));
            }
            cpu_normal_deg.push_back(angle(unit(gradient), ref->normal));  // outward: −∇F
        }
    if (!dts.empty()) {
        std::sort(dts.begin(), dts.end());
        a.p99_dt = dts[std::size_t(0.99 * double(dts.size() - 1))];
        a.max_dt = dts.back();
        std::sort(normal_deg.begin(), normal_deg.end());
        std::sort(cpu_normal_deg.begin(), cpu_normal_deg.end());
        a.p99_normal_deg = normal_deg[std::size_t(0.99 * double(normal_deg.size() - 1))];
        a.p99_cpu_normal_deg = cpu_normal_deg[std::size_t(0.99 * double(cpu_normal_deg.size() - 1))];
    }
    return a;
}

}  // namespace

TEST(OdfShBasis, ShaderEvaluationMatchesSh2ampAndPlainCpu) {
    FIBLET_REQUIRE_PHANTOM_FOD();
    FIBLET_REQUIRE_GL();
    const Image crop = read_image(phantom_file("phantom-fod-crop.nii"));
    ASSERT_EQ(crop.volumes(), 45);
    // The crop's voxel of largest energy above l = 0 (the most lobed FOD).
    std::array<std::int64_t, 3> voxel{};
    double energy = -1;
    for (std::int64_t k = 0; k < 12; ++k)
        for (std::int64_t j = 0; j < 12; ++j)
            for (std::int64_t i = 0; i < 12; ++i) {
                double e = 0;
                for (std::int64_t v = 1; v < 45; ++v) e += double(crop.at(i, j, k, v)) * crop.at(i, j, k, v);
                if (e > energy) energy = e, voxel = {i, j, k};
            }
    const auto c = voxel_coefficients(crop, voxel[0], voxel[1], voxel[2]);
    const auto dirs = fibonacci_sphere(1000);
    const auto gpu = gpu_sh_values(c, 8, dirs);
    double worst_plain = 0, worst_recurrence = 0, peak = 0;
    for (std::size_t i = 0; i < dirs.size(); ++i) {
        const double plain = plain_sh_value(c, 8, dirs[i]);
        peak = std::max(peak, std::abs(plain));
        worst_plain = std::max(worst_plain, std::abs(gpu[i] - plain));
        worst_recurrence = std::max(worst_recurrence, std::abs(viewer::sh_value<double>(c, 8, dirs[i][0], dirs[i][1], dirs[i][2]) - plain));
    }
    std::printf("SH basis at 1000 directions, lmax 8 (peak |f| %.4f): |GPU - plain CPU| max %.3g; CPU recurrence %.3g\n", peak,
                worst_plain, worst_recurrence);
    EXPECT_GT(peak, 0.1);
    EXPECT_LE(worst_plain, 1e-5);
    EXPECT_LE(worst_recurrence, 1e-12);

    // MRtrix3's own evaluation of the same image (Debian mrtrix3).
    if (std::system("command -v sh2amp >/dev/null 2>&1") != 0) GTEST_SKIP() << "no sh2amp (Debian mrtrix3; scripts/setup.sh)";
    const TempDir dir;
    {
        std::ofstream out(dir.file("dirs.txt"));
        out.precision(17);
        for (const auto& d : dirs) out << d[0] << ' ' << d[1] << ' ' << d[2] << '\n';
    }
    const std::string cmd = "sh2amp -quiet -force " + phantom_file("phantom-fod-crop.nii") + " " + dir.file("dirs.txt") +
                            " " + dir.file("amp.nii");
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    const Image amp = read_image(dir.file("amp.nii"));
    ASSERT_EQ(amp.volumes(), 1000);
    double worst_sh2amp = 0;
    for (std::size_t i = 0; i < dirs.size(); ++i)
        worst_sh2amp = std::max(worst_sh2amp, std::abs(gpu[i] - double(amp.at(voxel[0], voxel[1], voxel[2], std::int64_t(i)))));
    std::printf("|GPU - sh2amp| max %.3g (voxel %lld %lld %lld: %g vs %g)\n", worst_sh2amp, (long long)voxel[0],
                (long long)voxel[1], (long long)voxel[2], gpu[0], double(amp.at(voxel[0], voxel[1], voxel[2], 0)));
    EXPECT_LE(worst_sh2amp, 1e-5);
}

// The GLSL twin of sh_value_and_gradient (the glyphs' normals) against the
// CPU's in double: the phantom's crossing voxel in glyph units, lmax 8.
TEST(OdfShBasis, ShaderGradientMatchesCpu) {
    FIBLET_REQUIRE_PHANTOM_FOD();
    FIBLET_REQUIRE_GL();
    const std::vector<float> raw = crossing_voxel(phantom_fod());
    const double bound = viewer::sh_amplitude_bound(raw.data(), 8);
    std::vector<float> c;
    for (int i = 0; i < viewer::sh_coefficient_count(8); ++i) c.push_back(float(raw[std::size_t(i)] / bound));
    const auto dirs = fibonacci_sphere(1000);
    const auto gpu = gpu_sh_gradients(c, 8, dirs);
    double worst_gradient = 0, worst_value = 0, largest = 0, worst_tangential = 0;
    for (std::size_t i = 0; i < dirs.size(); ++i) {
        double g[3];
        const double f = viewer::sh_value_and_gradient<double>(c, 8, dirs[i][0], dirs[i][1], dirs[i][2], g);
        worst_value = std::max(worst_value, std::abs(gpu[i][3] - f));
        for (int a = 0; a < 3; ++a) worst_gradient = std::max(worst_gradient, std::abs(gpu[i][std::size_t(a)] - g[a]));
        largest = std::max(largest, std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]));
        worst_tangential = std::max(worst_tangential, std::abs(viewer::dot3(dirs[i], V3{gpu[i][0], gpu[i][1], gpu[i][2]})));
    }
    std::printf("SH gradient at 1000 directions, lmax 8, glyph units (largest |grad_S f| %.3f): |GPU - CPU| max %.3g, "
                "value %.3g; radial part of the GPU's gradient max %.3g\n",
                largest, worst_gradient, worst_value, worst_tangential);
    EXPECT_GT(largest, 0.5);
    EXPECT_LE(worst_gradient, 1e-5);
    EXPECT_LE(worst_value, 1e-5);
    EXPECT_LE(worst_tangential, 1e-5);
}

TEST(OdfShBasis, Descoteaux07IsRewrittenIntoMrtrix) {
    // dipy's legacy basis: m > 0 -> √2 Im Y_l^m, m < 0 -> √2 Re Y_l^|m|,
    // with the Condon–Shortley phase (scipy's sph_harm).
    std::mt19937 rng(7);
    std::normal_distribution<double> n(0, 1);
    std::vector<float> c(45);
    for (auto& v : c) v = float(n(rng));
    std::vector<float> converted = c;
    viewer::descoteaux07_to_mrtrix(converted, 8);
    for (const auto& u : fibonacci_sphere(200)) {
        const double theta = std::acos(u[2]), phi = std::atan2(u[1], u[0]);
        double dipy = 0;
        for (int l = 0; l <= 8; l += 2)
            for (int m = -l; m <= l; ++m) {
                const int am = std::abs(m);
                const double k = std::sqrt((2 * l + 1) / (4 * M_PI) * std::tgamma(l - am + 1) / std::tgamma(l + am + 1));
                const double p = (am % 2 ? -1.0 : 1.0) * k * std::assoc_legendre(unsigned(l), unsigned(am), std::cos(theta));
                const double y = m == 0 ? p : m > 0 ? std::sqrt(2.0) * p * std::sin(am * phi) : std::sqrt(2.0) * p * std::cos(am * phi);
                dipy += c[std::size_t(viewer::sh_index(l, m))] * y;
            }
        EXPECT_NEAR(viewer::sh_value<double>(converted, 8, u[0], u[1], u[2]), dipy, 1e-5);
    }
}

class OdfGlyphsSingle : public ::testing::TestWithParam<int> {};

TEST_P(OdfGlyphsSingle, GpuMatchesCpuRootFindingInDouble) {
    FIBLET_REQUIRE_PHANTOM_FOD();
    FIBLET_REQUIRE_GL();
    const int lmax = GetParam();
    static const std::vector<float> crossing = crossing_voxel(phantom_fod());
    const GlyphAgreement a = compare_single_glyph(crossing, lmax);
    std::printf("lmax %d, 256x256: hit/miss agree %.4f%% (%d of %d), both hit %d, |dt| p99 %.3g max %.3g (glyph units = "
                "mm, bounding radius 1), max | |p| - |f(p^)| | %.3g, max box excess %.3g; normals p99: GPU vs CPU %.2f deg, "
                "CPU vs a difference of F %.2g deg\n",
                lmax, 100.0 * a.agree / a.pixels, a.agree, a.pixels, a.both, a.p99_dt, a.max_dt, a.max_radius_error,
                a.max_box_excess, a.p99_normal_deg, a.p99_cpu_normal_deg);
    EXPECT_GT(a.both, 2000);
    EXPECT_GE(double(a.agree) / a.pixels, 0.999);
    EXPECT_LE(a.p99_dt, 1e-4);
    EXPECT_LE(a.max_radius_error, 1e-3);
    EXPECT_LE(a.max_box_excess, 1e-4);  // no hit outside the box
    EXPECT_LE(a.p99_normal_deg, 2.0);     // 8-bit colour holds about 0.5°
    EXPECT_LE(a.p99_cpu_normal_deg, 0.01);
}
INSTANTIATE_TEST_SUITE_P(OdfLmax, OdfGlyphsSingle, ::testing::Values(4, 8));

// Glyphs whose polynomial loses degree or touches the bounding sphere: an
// isotropic ODF (l = 0 alone, as a CSF voxel or an lmax-0 image) is the
// bounding sphere itself, and every ray's leading coefficient f(d)^2 - 1
// vanishes; single coefficients of each order; negative lobes. Each is
// drawn, matches the CPU reference, and both match a march along the ray.
struct DegenerateGlyph {
    const char* name;
    int lmax;
    std::vector<std::pair<std::pair<int, int>, float>> terms;  // (l, m) -> coefficient
};
void PrintTo(const DegenerateGlyph& g, std::ostream* os) { *os << g.name; }  // stable test names
class OdfGlyphsDegenerate : public ::testing::TestWithParam<DegenerateGlyph> {};

TEST_P(OdfGlyphsDegenerate, DrawnAsTheCpuReferenceAndAMarchAlongTheRay) {
    FIBLET_REQUIRE_GL();
    const DegenerateGlyph& g = GetParam();
    std::vector<float> c(std::size_t(viewer::sh_coefficient_count(g.lmax)), 0.0f);
    for (const auto& [lm, v] : g.terms) c[std::size_t(viewer::sh_index(lm.first, lm.second))] = v;
    const GlyphAgreement a = compare_single_glyph(c, g.lmax, 40);
    std::printf("%s (lmax %d): GPU and CPU hit %d of %d pixels, agree %.3f%%, |dt| max %.3g, radius error %.3g; "
                "march (%d rays): CPU agrees %.3f%%, GPU %.3f%%, |t - t_march| max %.3g\n",
                g.name, g.lmax, a.both, a.pixels, 100.0 * a.agree / a.pixels, a.max_dt,
                a.max_radius_error, a.marched, 100.0 * a.march_agree_cpu / a.marched,
                100.0 * a.march_agree_gpu / a.marched, a.max_march_dt);
    EXPECT_GT(a.both, 1000);
    EXPECT_LT(a.both, a.pixels);  // the outline is in view
    EXPECT_GE(double(a.agree) / a.pixels, 0.999);
    EXPECT_GE(double(a.march_agree_cpu) / a.marched, 0.997);
    EXPECT_GE(double(a.march_agree_gpu) / a.marched, 0.997);
    EXPECT_LE(a.max_march_dt, 1.5e-3);  // the march's step is 1e-3
    EXPECT_LE(a.max_radius_error, 1e-3);
    EXPECT_LE(a.max_box_excess, 1e-4);
}
INSTANTIATE_TEST_SUITE_P(
    Odf, OdfGlyphsDegenerate,
    ::testing::Values(DegenerateGlyph{"isotropic_lmax8", 8, {{{0, 0}, 0.28f}}},
                      DegenerateGlyph{"isotropic_negative", 4, {{{0, 0}, -0.5f}}},
                      DegenerateGlyph{"isotropic_lmax0", 0, {{{0, 0}, 1.0f}}},
                      DegenerateGlyph{"nearly_isotropic", 8, {{{0, 0}, 1.0f}, {{2, 0}, 1e-3f}}},
                      DegenerateGlyph{"only_y20", 2, {{{2, 0}, 1.0f}}},
                      DegenerateGlyph{"only_y4_3", 8, {{{4, 3}, 0.7f}}},
                      DegenerateGlyph{"only_y8_minus5", 8, {{{8, -5}, -0.3f}}},
                      DegenerateGlyph{"negative_lobes", 4, {{{0, 0}, 0.2f}, {{2, 0}, -1.0f}, {{4, 2}, 0.4f}}}),
    [](const ::testing::TestParamInfo<DegenerateGlyph>& info) { return std::string(info.param.name); });

TEST(OdfGlyphs, BoundingBoxesHoldTheSurface) {
    FIBLET_REQUIRE_PHANTOM_FOD();
    viewer::GlyphSetOptions o;
    o.axis = 2, o.index = 50;
    const viewer::GlyphSet set = viewer::make_glyph_set(phantom_fod(), o);
    ASSERT_GT(set.centers.size(), 1000u);
    std::mt19937 rng(17);
    std::uniform_int_distribution<std::size_t> glyph(0, set.centers.size() - 1);
    std::normal_distribution<double> n(0, 1);
    ASSERT_EQ(set.extents.size(), set.centers.size());
    double worst_cube = 0, worst_tight = 0;
    for (int i = 0; i < 100000; ++i) {
        const std::size_t g = glyph(rng);
        const V3 u = unit(V3{n(rng), n(rng), n(rng)});
        const std::vector<float> c(set.coefficients.begin() + long(g) * set.coefficients_per_glyph,
                                   set.coefficients.begin() + long(g + 1) * set.coefficients_per_glyph);
        const double r = std::abs(viewer::sh_value<double>(c, set.lmax, u[0], u[1], u[2]));
        for (int a = 0; a < 3; ++a) {
            worst_cube = std::max(worst_cube, std::abs(r * u[std::size_t(a)]));
            worst_tight = std::max(worst_tight, std::abs(r * u[std::size_t(a)]) / double(set.extents[g][std::size_t(a)]));
        }
    }
    double volume = 0;
    for (const auto& e : set.extents) volume += double(e[0]) * e[1] * e[2] / double(set.extents.size());
    std::printf("10^5 surface points of %zu glyphs: largest |coordinate| %.4f of the bound's cube (1), %.4f of the tight "
                "box's half size; tight boxes hold %.1f %% of the cube's volume on average\n",
                set.centers.size(), worst_cube, worst_tight, 100 * volume);
    EXPECT_LE(worst_cube, 1.0);
    EXPECT_LE(worst_tight, 1.0);
}

// The normals' closed form (glyph_normal: one SH evaluation with its
// gradient, sh_value_and_gradient) at surface points x = |f(u)| u of every
// glyph of the phantom's axial slice 50, lmax 8 and 4 (the glyph set's
// coefficients, lmax 4 by dropping the higher degrees), against −∇F by central
// differences in double (steps 1e-5 |x|); and ∇_S f against differences of f
// along two tangents.
class OdfGlyphNormals : public ::testing::TestWithParam<int> {};

TEST_P(OdfGlyphNormals, ClosedFormMatchesDifferencesOfF) {
    FIBLET_REQUIRE_PHANTOM_FOD();
    const int lmax = GetParam();
    viewer::GlyphSetOptions o;
    o.axis = 2, o.index = 50, o.lmax = lmax, o.tight_boxes = false;
    const viewer::GlyphSet set = viewer::make_glyph_set(phantom_fod(), o);
    ASSERT_GT(set.centers.size(), 1000u);
    ASSERT_EQ(set.lmax, lmax);
    std::mt19937 rng(lmax);
    std::normal_distribution<double> n(0, 1);
    std::vector<double> deg;
    double worst_value = 0, worst_gradient = 0;
    for (std::size_t g = 0; g < set.centers.size(); ++g) {
        const std::vector<double> c(set.coefficients.begin() + long(g) * set.coefficients_per_glyph,
                                    set.coefficients.begin() + long(g + 1) * set.coefficients_per_glyph);
        for (int i = 0; i < 8; ++i) {
            const V3 u = unit(V3{n(rng), n(rng), n(rng)});
            double grad[3];
            const double f = viewer::sh_value_and_gradient<double>(c, lmax, u[0], u[1], u[2], grad);
            worst_value = std::max(worst_value, std::abs(f - viewer::sh_value<double>(c, lmax, u[0], u[1], u[2])));
            // ∇_S f along two tangents against differences of f on the sphere.
            const V3 t1 = unit(cross(u, std::abs(u[0]) < 0.9 ? V3{1, 0, 0} : V3{0, 1, 0})), t2 = cross(u, t1);
            for (const V3& t : {t1, t2}) {
                const double h = 1e-5;
                const V3 a = unit(add(u, mul(h, t))), b = unit(sub(u, mul(h, t)));
                const double difference = (viewer::sh_value<double>(c, lmax, a[0], a[1], a[2]) -
                                           viewer::sh_value<double>(c, lmax, b[0], b[1], b[2])) / (2 * h);
                worst_gradient = std::max(worst_gradient, std::abs(difference - viewer::dot3(V3{grad[0], grad[1], grad[2]}, t)));
            }
            const double r = std::abs(f);
            if (r < 1e-3) continue;  // the glyph pinches to its centre there
            const V3 x = mul(r, u);
            const V3 normal = viewer::glyph_normal<double>(c, lmax, x);
            V3 minus_gradient;
            for (int axis = 0; axis < 3; ++axis) {
                V3 e{0, 0, 0};
                e[std::size_t(axis)] = 1e-5 * r;
                minus_gradient[std::size_t(axis)] = glyph_function(c, lmax, sub(x, e)) - glyph_function(c, lmax, add(x, e));
            }
            const V3 d = unit(minus_gradient);
            deg.push_back(std::atan2(norm(cross(d, normal)), viewer::dot3(d, normal)) * 180 / M_PI);
        }
    }
    std::sort(deg.begin(), deg.end());
    const double p99 = deg[std::size_t(0.99 * double(deg.size() - 1))];
    std::printf("lmax %d, %zu surface points of %zu glyphs: closed-form normal vs -grad F by differences: median %.2g deg, "
                "p99 %.2g deg, max %.2g deg; |f - sh_value| max %.2g; grad_S f vs differences of f max %.2g\n",
                lmax, deg.size(), set.centers.size(), deg[deg.size() / 2], p99, deg.back(), worst_value, worst_gradient);
    EXPECT_GT(deg.size(), 10000u);
    EXPECT_LE(p99, 0.01);
    EXPECT_LE(deg.back(), 0.1);
    EXPECT_LE(worst_value, 1e-13);
    EXPECT_LE(worst_gradient, 1e-8);
}
INSTANTIATE_TEST_SUITE_P(OdfLmax, OdfGlyphNormals, ::testing::Values(4, 8));

TEST(OdfGlyphs, PeaksFollowTheDecodedFibers) {
    FIBLET_REQUIRE_PHANTOM_FOD();
    if (!shared_data_available()) GTEST_SKIP() << "no shared data";
    const Image& fod = phantom_fod();
    const TempDir dir;
    // The phantom's SD_STREAM tractogram, compressed and decoded again.
    const FftFile file(compress_into(dir, shared_data("small-sdstream.tck"), "s.fft"));
    const CpuDecoded decoded = cpu_decode_blocks(file);
    // Decoded steps binned by voxel of the FOD image.
    const Affine3x4 to_voxel = inverse(fod.voxel_to_world);
    std::map<std::array<std::int64_t, 3>, std::vector<V3>> tangents;
    for (std::size_t b = 0; b + 1 < decoded.block_first.size(); ++b)
        for (std::size_t i = decoded.block_first[b]; i + 1 < decoded.block_first[b + 1]; ++i) {
            const V3 p = v3(decoded.point(i)), q = v3(decoded.point(i + 1));
            const auto v = transform_point(to_voxel, {0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2])});
            tangents[{std::llround(v[0]), std::llround(v[1]), std::llround(v[2])}].push_back(unit(sub(q, p)));
        }
    const auto dirs = fibonacci_sphere(4000);
    int single = 0, within = 0;
    std::vector<double> angles;
    for (const std::int64_t slice : {30, 40, 50, 60, 70}) {
        viewer::GlyphSetOptions o;
        o.axis = 2, o.index = slice;
        const viewer::GlyphSet set = viewer::make_glyph_set(fod, o);
        for (std::size_t g = 0; g < set.centers.size(); ++g) {
            const auto it = tangents.find(set.voxels[g]);
            if (it == tangents.end() || it->second.size() < 20) continue;
            const std::vector<float> c(set.coefficients.begin() + long(g) * set.coefficients_per_glyph,
                                       set.coefficients.begin() + long(g + 1) * set.coefficients_per_glyph);
            std::vector<double> v;
            for (const auto& d : dirs) v.push_back(viewer::sh_value<double>(c, set.lmax, d[0], d[1], d[2]));
            const std::size_t top = std::size_t(std::max_element(v.begin(), v.end()) - v.begin());
            // One bundle: nothing above a fifth of the peak further than 45° from its axis.
            bool one = true;
            for (std::size_t i = 0; i < dirs.size() && one; ++i)
                one = !(std::abs(viewer::dot3(dirs[i], dirs[top])) < std::cos(45 * M_PI / 180) && v[i] > 0.2 * v[top]);
            if (!one) continue;
            V3 mean{0, 0, 0};
            for (const V3& t : it->second) mean = add(mean, mul(viewer::dot3(t, dirs[top]) >= 0 ? 1.0 : -1.0, t));
            const double angle = std::acos(std::min(1.0, std::abs(viewer::dot3(unit(mean), dirs[top])))) * 180 / M_PI;
            ++single;
            within += angle <= 20;
            angles.push_back(angle);
        }
    }
    ASSERT_GT(single, 50);
    std::sort(angles.begin(), angles.end());
    std::printf("%d single-bundle voxels of axial slices 30..70 (every 10th) with >= 20 decoded steps: glyph peak vs "
                "mean decoded tangent median %.2f deg, p95 %.2f, max %.2f; %d within 20 deg\n",
                single, angles[angles.size() / 2], angles[std::size_t(0.95 * double(angles.size() - 1))], angles.back(), within);
    EXPECT_EQ(within, single);
}

TEST(ImageSlice, PixelsShowTheVoxelsUnderAKnownCamera) {
    FIBLET_REQUIRE_PHANTOM_FOD();
    FIBLET_REQUIRE_GL();
    // The first volume of the 4-D crop: 12 × 12 voxels of 1 mm, z slice 5.
    const Image crop = read_image(phantom_file("phantom-fod-crop.nii"));
    const viewer::SliceImage slice = viewer::make_slice_image(crop, 2, 5);
    const auto overlay = std::make_shared<viewer::ImageSliceOverlay>(slice);
    const auto centre = transform_point(crop.voxel_to_world, {5.5, 5.5, 5});
    Camera cam;
    cam.position = {float(centre[0]) + 1.3f, float(centre[1]) - 2.1f, float(centre[2]) + 20};
    cam.target = {float(centre[0]), float(centre[1]), float(centre[2])};
    cam.up = {0, 1, 0};
    cam.fov_y_deg = 40, cam.aspect = 1, cam.near_mm = 1, cam.far_mm = 100;
    const int w = 200, h = 200;
    const OverlayFrame frame = render_overlays({overlay}, cam, w, h);
    const Affine3x4 to_voxel = inverse(crop.voxel_to_world);
    int compared = 0, matched = 0, outside_black = 0, outside = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Ray ray = pixel_ray(cam, w, h, x, y);
            const double t = (centre[2] - ray.origin[2]) / ray.dir[2];
            const V3 p = add(ray.origin, mul(t, ray.dir));
            const auto v = transform_point(to_voxel, {p[0], p[1], p[2]});
            const std::uint8_t grey = frame.rgba[std::size_t(4 * (y * w + x))];
            const bool inside = v[0] > -0.5 && v[1] > -0.5 && v[0] < 11.5 && v[1] < 11.5;
            // Away from voxel edges, where the pixel centre's side is a matter of rounding.
            const double fx = v[0] + 0.5 - std::floor(v[0] + 0.5), fy = v[1] + 0.5 - std::floor(v[1] + 0.5);
            if (std::min({fx, 1 - fx, fy, 1 - fy}) < 0.02) continue;
            if (!inside) {
                ++outside;
                outside_black += grey == 0;
                continue;
            }
            const float value = crop.at(std::llround(v[0]), std::llround(v[1]), 5, 0);
            const double expected = 255.0 * std::clamp((value - slice.min) / (slice.max - slice.min), 0.0f, 1.0f);
            ++compared;
            matched += std::abs(double(grey) - expected) <= 1.0;
        }
    std::printf("slice pixels: %d of %d match their voxel's grey within 1/255; %d of %d outside the grid black\n", matched,
                compared, outside_black, outside);
    EXPECT_GT(compared, 10000);
    EXPECT_EQ(matched, compared);
    EXPECT_EQ(outside_black, outside);
}

TEST(OdfCli, RenderDrawsGlyphsOverASliceAndChecksItsOptions) {
    FIBLET_REQUIRE_PHANTOM_FOD();
    FIBLET_REQUIRE_GL();
    if (!shared_data_available()) GTEST_SKIP() << "no shared data";
    const TempDir dir;
    const std::string fft = compress_into(dir, shared_data("bundles/CST_R.tck"), "cst.fft");
    const std::string crop = phantom_file("phantom-fod-crop.nii"), png = dir.file("g.png");
    // The crop's middle coronal slice from the front, its glyphs over its first volume.
    const CommandResult r = run_cli("render " + fft + " --odf " + crop + " --odf-slice y:6 --image " + crop +
                                    " --slice y:6 --slab 4 --camera 0.5,-25,0.5,0.5,0.5,0.5,0,0,1 --size 160x160 -o " + png);
    ASSERT_EQ(r.status, 0) << r.output;
    const viewer::RgbaImage im = viewer::read_png(png);
    std::size_t grey = 0, coloured = 0;
    for (std::size_t i = 0; i < im.rgba.size(); i += 4) {
        const int red = im.rgba[i], green = im.rgba[i + 1], blue = im.rgba[i + 2];
        grey += red == green && green == blue && red > 0;
        coloured += std::max({red, green, blue}) - std::min({red, green, blue}) > 40;
    }
    EXPECT_GT(grey, 5000u);
    EXPECT_GT(coloured, 500u);

    const auto fails_with = [&](const std::string& options, const std::string& message) {
        const CommandResult bad = run_cli("render " + fft + " -f -o " + png + " " + options);
        EXPECT_NE(bad.status, 0) << options;
        EXPECT_NE(bad.output.find(message), std::string::npos) << options << ": " << bad.output;
    };
    fails_with("--slab 3", "--slab needs");
    fails_with("--odf " + phantom_file("phantom-mask.nii"), "not an SH image");
    fails_with("--odf " + crop + " --odf-slice z:12", "outside 0..11");
    fails_with("--odf " + crop + " --odf-lmax 10", "at most the image's lmax 8");
    fails_with("--odf " + crop + " --sh-basis tournier07", "not mrtrix or descoteaux07");
    fails_with("--image " + crop + " --slice w:3", "not AXIS:INDEX");
}

// --slab: every fiber pixel drawn, in each style, lies within the slab.
// The reproduction: a 3x3x3 SH image (lmax 2) with only the centre
// voxel's Y00 set draws a sphere, as large as the same glyph with 1e-3 Y20
// added (which was drawn right before the chord's ends moved off the
// bounding sphere); and an lmax-0 image (one volume) draws it too.
TEST(OdfCli, IsotropicGlyphsAreDrawn) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string fft = compress_fibers(dir, {{{40, 40, 40}, {40.5f, 40, 40}, {41, 40, 40}}}, "far");
    const auto glyph_pixels = [&](const std::string& name, std::int64_t volumes, float y20) {
        SourceImage image;
        image.dims = {3, 3, 3, volumes};
        image.fill([&](std::int64_t i, std::int64_t j, std::int64_t k, std::int64_t v) {
            if (i != 1 || j != 1 || k != 1) return 0.0f;
            return v == 0 ? 1.0f : v == 3 ? y20 : 0.0f;  // Y00; Y20 is volume 3
        });
        const std::string mif = dir.file(name + ".mif"), png = dir.file(name + ".png");
        image.write_mif(mif);
        const CommandResult r = run_cli("render " + fft + " --odf " + mif + " --odf-slice z:1 --camera 1,-6,1,1,1,1,0,0,1 " +
                                        "--size 128x128 -f -o " + png);
        EXPECT_EQ(r.status, 0) << r.output;
        const viewer::RgbaImage im = viewer::read_png(png);
        std::size_t drawn = 0;  // pixels unlike the corner's background
        for (std::size_t i = 0; i < im.rgba.size(); i += 4)
            drawn += !std::equal(im.rgba.begin() + long(i), im.rgba.begin() + long(i) + 3, im.rgba.begin());
        return drawn;
    };
    const std::size_t iso = glyph_pixels("iso", 6, 0), nearly = glyph_pixels("nearly", 6, 1e-3f),
                      lmax0 = glyph_pixels("lmax0", 1, 0);
    std::printf("glyph pixels at 128x128: isotropic %zu, with 1e-3 Y20 %zu, lmax-0 image %zu\n", iso, nearly, lmax0);
    EXPECT_GT(nearly, 500u);
    EXPECT_NEAR(double(iso), double(nearly), 0.02 * double(nearly));
    EXPECT_EQ(lmax0, iso);
}

TEST(ViewerSlab, OnlyFibersWithinTheSlabAreDrawn) {
    FIBLET_REQUIRE_GL();
    if (!shared_data_available()) GTEST_SKIP() << "no shared data";
    const CompressedScene compressed(shared_data("bundles/CST_R.tck"));
    const viewer::GpuScene& scene = compressed.scene;
    const Vec3f c = scene.bounds().center();
    Camera cam;
    cam.position = {c.x + 30, c.y - 60, c.z + 20};
    cam.target = c;
    cam.up = {0, 0, 1};
    cam.fov_y_deg = 50, cam.aspect = 1, cam.near_mm = 5, cam.far_mm = 300;
    for (const viewer::DrawStyle style : {viewer::DrawStyle::lines, viewer::DrawStyle::tubes, viewer::DrawStyle::capsules}) {
        viewer::Renderer renderer(*viewer_gl().programs);
        viewer::RenderOptions o;
        o.style = style;
        o.level_of_detail = false;
        viewer::RenderTarget all(128, 128), slab(128, 128);
        renderer.render(scene, cam, o, all);
        o.slab_plane = {0, 0, 1, c.z};
        o.slab_half_width_mm = 2;
        renderer.render(scene, cam, o, slab);
        const auto fibers_all = all.read_fibers(), fibers = slab.read_fibers();
        const auto depth = slab.read_depth();
        std::size_t drawn = 0, drawn_all = 0, outside = 0;
        for (int y = 0; y < 128; ++y)
            for (int x = 0; x < 128; ++x) {
                const std::size_t i = std::size_t(y * 128 + x);
                drawn_all += fibers_all[i] != 0;
                if (fibers[i] == 0) continue;
                ++drawn;
                const Ray ray = pixel_ray(cam, 128, 128, x, y);
                const V3 p = add(ray.origin, mul(depth_to_distance(cam, depth[i], ray), ray.dir));
                outside += std::abs(p[2] - c.z) > 2 + 0.05;
            }
        EXPECT_GT(drawn, 20u) << viewer::draw_style_name(style);
        EXPECT_LT(drawn, drawn_all / 2) << viewer::draw_style_name(style);
        EXPECT_EQ(outside, 0u) << viewer::draw_style_name(style);
    }
}

// Glyphs and fibers share the depth buffer: a fiber through the glyph's
// centre is hidden where the glyph lies in front of it, one in front of
// the glyph is drawn over it.
TEST(OdfGlyphs, GlyphsAndFibersOccludeEachOther) {
    FIBLET_REQUIRE_PHANTOM_FOD();
    FIBLET_REQUIRE_GL();
    static const std::vector<float> crossing = crossing_voxel(phantom_fod());
    viewer::GlyphSet set;
    set.lmax = 8;
    set.coefficients_per_glyph = 45;
    const double bound = viewer::sh_amplitude_bound(crossing.data(), 8);
    for (int i = 0; i < 45; ++i) set.coefficients.push_back(float(crossing[std::size_t(i)] / bound));
    set.centers.push_back({0, 0, 0, 1});
    const auto glyph = std::make_shared<viewer::OdfGlyphsOverlay>(set);
    Camera cam;
    cam.position = {0.3f, -0.2f, 6};
    cam.target = {0, 0, 0};
    cam.up = {0, 1, 0};
    cam.fov_y_deg = 25, cam.aspect = 1, cam.near_mm = 1, cam.far_mm = 20;
    const int w = 128, h = 128;
    const OverlayFrame alone = render_overlays({glyph}, cam, w, h);
    for (const float z : {0.0f, 2.0f}) {
        const TempDir dir;
        // Fibers across the whole view, in the plane z, along x and y.
        std::vector<std::vector<Vec3f>> fibers;
        for (int f = -4; f <= 4; ++f) {
            std::vector<Vec3f> along_x, along_y;
            for (int i = -30; i <= 30; ++i) {
                along_x.push_back({0.1f * float(i), 0.25f * float(f), z});
                along_y.push_back({0.25f * float(f), 0.1f * float(i), z});
            }
            fibers.push_back(along_x), fibers.push_back(along_y);
        }
        const FftFile file(compress_fibers(dir, fibers, "grid"));
        const viewer::GpuScene scene(file, *viewer_gl().programs);
        viewer::Renderer renderer(*viewer_gl().programs);
        renderer.set_overlays({glyph});
        viewer::RenderTarget target(w, h);
        viewer::RenderOptions o;
        o.level_of_detail = false;
        renderer.render(scene, cam, o, target);
        const auto ids = target.read_fibers();
        std::size_t over_glyph = 0, beside = 0, glyph_in_front = 0, on_silhouette = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const std::size_t i = std::size_t(y * w + x);
                const bool fiber = ids[i] != 0;
                if (alone.depth[i] >= 1.0f) {
                    beside += fiber;
                    continue;
                }
                on_silhouette += fiber;
                const Ray ray = pixel_ray(cam, w, h, x, y);
                const double hit_z = add(ray.origin, mul(depth_to_distance(cam, alone.depth[i], ray), ray.dir))[2];
                if (hit_z > z + 0.02) glyph_in_front += 1, over_glyph += fiber;
            }
        std::printf("fibers at z = %.0f: %zu fiber pixels beside the glyph, %zu on it; %zu of %zu glyph pixels in front "
                    "of the fibers' plane show a fiber\n", double(z), beside, on_silhouette, over_glyph, glyph_in_front);
        EXPECT_GT(beside, 200u);
        if (z == 0.0f) {
            EXPECT_GT(glyph_in_front, 100u);
            EXPECT_EQ(over_glyph, 0u);
        } else {
            EXPECT_EQ(glyph_in_front, 0u);  // the glyph lies below z = 1
            EXPECT_GT(on_silhouette, 10u);  // lines over the glyph are drawn
        }
    }
}

// The same SH image as MRtrix .mif (mrconvert) gives the same glyphs.
// The renderer widens the camera's near and far planes to the overlays'
// boxes: a glyph and a slice through it, drawn with planes that cut
// through both (0.02 mm apart around the centre), look as with planes around
// them; clip_planes_covering leaves planes that already hold them alone.
TEST(OdfGlyphs, ClipPlanesCoverTheOverlays) {
    FIBLET_REQUIRE_PHANTOM_FOD();
    FIBLET_REQUIRE_GL();
    static const std::vector<float> crossing = crossing_voxel(phantom_fod());
    viewer::GlyphSet set;
    set.lmax = 8;
    set.coefficients_per_glyph = viewer::sh_coefficient_count(8);
    const double bound = viewer::sh_amplitude_bound(crossing.data(), 8);
    for (int i = 0; i < set.coefficients_per_glyph; ++i) set.coefficients.push_back(float(crossing[std::size_t(i)] / bound));
    set.centers.push_back({0, 0, 0, 1});
    set.extents.push_back(viewer::glyph_box_extents(set.coefficients, 8, viewer::fibonacci_half_sphere(512)));
    viewer::SliceImage slice;
    slice.width = slice.height = 2;
    slice.values = {0, 1, 2, 3};
    slice.min = 0, slice.max = 3;
    slice.corners = {{{-1.5f, -1.5f, 0.2f}, {1.5f, -1.5f, 0.2f}, {-1.5f, 1.5f, 0.2f}, {1.5f, 1.5f, 0.2f}}};
    const std::vector<std::shared_ptr<viewer::Overlay>> overlays{std::make_shared<viewer::ImageSliceOverlay>(slice),
                                                                 std::make_shared<viewer::OdfGlyphsOverlay>(set)};
    Camera wide;
    wide.position = {2.2f, -2.9f, 1.7f};
    wide.target = {0, 0, 0};
    wide.up = {0, 0, 1};
    wide.fov_y_deg = 40;
    wide.aspect = 1;
    wide.near_mm = 0.5f, wide.far_mm = 10;
    const float distance = std::sqrt(2.2f * 2.2f + 2.9f * 2.9f + 1.7f * 1.7f);
    Camera narrow = wide;
    narrow.near_mm = distance - 0.01f, narrow.far_mm = distance + 0.01f;
    const Camera covering = viewer::clip_planes_covering(narrow, overlays);
    const Camera unchanged = viewer::clip_planes_covering(wide, overlays);
    EXPECT_EQ(unchanged.near_mm, wide.near_mm);
    EXPECT_EQ(unchanged.far_mm, wide.far_mm);
    EXPECT_LT(covering.near_mm, distance - 1.4f);  // the slice's corner nearest the camera
    EXPECT_GT(covering.far_mm, distance + 1.4f);
    const int w = 128, h = 128;
    const OverlayFrame a = render_overlays(overlays, wide, w, h), b = render_overlays(overlays, narrow, w, h);
    int drawn = 0, differ = 0;
    for (std::size_t i = 0; i < a.depth.size(); ++i) {
        drawn += a.depth[i] < 1.0f;
        differ += (a.depth[i] < 1.0f) != (b.depth[i] < 1.0f);
        for (int c = 0; c < 3; ++c) differ += std::abs(int(a.rgba[4 * i + std::size_t(c)]) - int(b.rgba[4 * i + std::size_t(c)])) > 1;
    }
    std::printf("planes %.3f..%.3f mm widened to %.3f..%.3f: %d pixels drawn, %d differ from planes 0.5..10\n", narrow.near_mm,
                narrow.far_mm, covering.near_mm, covering.far_mm, drawn, differ);
    EXPECT_GT(drawn, 2000);
    EXPECT_EQ(differ, 0);
}

TEST(OdfGlyphs, MifAndNiftiGiveTheSameGlyphs) {
    FIBLET_REQUIRE_PHANTOM_FOD();
    if (std::system("command -v mrconvert >/dev/null 2>&1") != 0) GTEST_SKIP() << "no mrconvert (Debian mrtrix3)";
    const TempDir dir;
    const std::string cmd = "mrconvert -quiet -force " + phantom_file("phantom-fod-crop.nii") + " " + dir.file("crop.mif");
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    viewer::GlyphSetOptions o;
    o.axis = 1, o.index = 6;
    const viewer::GlyphSet nii = viewer::make_glyph_set(read_image(phantom_file("phantom-fod-crop.nii")), o);
    const viewer::GlyphSet mif = viewer::make_glyph_set(read_image(dir.file("crop.mif")), o);
    ASSERT_GT(nii.centers.size(), 50u);
    EXPECT_EQ(nii.centers, mif.centers);
    EXPECT_EQ(nii.coefficients, mif.coefficients);
}
