// Per-point values (--point-values): the .tsf reader against files written
// here byte by byte, renders coloured by the values against a CPU colouring
// of the same values, and the command line's refusals.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "cli_runner.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/streamline_field.hpp"
#include "overlays/color_bar/color_bar.hpp"
#include "overlays/color_bar/color_bar_font.hpp"
#include "render/render_target.hpp"
#include "window/orbit_camera.hpp"
#include "render/renderer.hpp"
#include "scene/colormaps.hpp"
#include "scene/gpu_scene.hpp"
#include "scene/point_values.hpp"
#include "viewer_test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;

namespace {

// A .tsf as MRtrix3 writes it: the text header, the data at `file: . OFFSET`,
// NaN after each streamline and Inf at the end (unless `ended` is false).
std::string tsf_bytes(const std::vector<std::vector<double>>& tracks, const std::string& datatype = "Float32LE",
                      bool ended = true) {
    std::string header = "mrtrix track scalars\ntimestamp: 1.5\ndatatype: " + datatype + "\ncount: " +
                         std::to_string(tracks.size()) + "\nfile: . 128\nEND\n";
    header.resize(128, '\0');
    const bool f64 = datatype.rfind("Float64", 0) == 0, be = datatype.size() > 7 && datatype.substr(7) == "BE";
    auto put = [&](double v) {
        unsigned char b[8];
        if (f64) {
            std::memcpy(b, &v, 8);
        } else {
            const float f = float(v);
            std::memcpy(b, &f, 4);
        }
        const std::size_t n = f64 ? 8 : 4;
        if (be == (std::endian::native == std::endian::little)) std::reverse(b, b + n);
        header.append(reinterpret_cast<const char*>(b), n);
    };
    for (const auto& t : tracks) {
        for (const double v : t) put(v);
        put(std::numeric_limits<double>::quiet_NaN());
    }
    if (ended) put(std::numeric_limits<double>::infinity());
    return header;
}

// A straight fiber along x from -20 to 20 mm, 0.5 mm apart (81 points).
std::vector<Vec3f> straight_fiber() {
    std::vector<Vec3f> f;
    for (int i = 0; i <= 80; ++i) f.push_back({-20.0f + 0.5f * float(i), 0, 0});
    return f;
}

// Its points' x as their values.
std::vector<float> x_values() {
    std::vector<float> values;
    for (const Vec3f& p : straight_fiber()) values.push_back(p.x);
    return values;
}

// A camera 60 mm up the z axis looking at the origin (30° field of view),
// and how far (mm) the image reaches along x from its centre.
struct TopView {
    Camera camera;
    double half_width_mm;
};
TopView top_view(int w, int h) {
    Camera cam;
    cam.position = {0, 0, 60}, cam.target = {0, 0, 0}, cam.up = {0, 1, 0};
    cam.fov_y_deg = 30, cam.aspect = float(w) / float(h), cam.near_mm = 1, cam.far_mm = 200;
    return {cam, std::tan(15.0 * M_PI / 180.0) * cam.aspect * 60.0};
}

}  // namespace

TEST(ViewerPointValues, ReadsTrackScalarFilesOfEveryDatatype) {
    const TempDir dir;
    const std::vector<std::vector<double>> tracks{{1, 2.5, -3}, {0.25}, {7, 8}};
    for (const std::string type : {"Float32LE", "Float32BE", "Float64LE", "Float64BE"}) {
        SCOPED_TRACE(type);
        write_file(dir.file("a.tsf"), tsf_bytes(tracks, type));
        const auto got = fiblet::read_track_scalars(dir.file("a.tsf"));
        ASSERT_EQ(got.size(), 3u);
        EXPECT_EQ(got[0], (std::vector<float>{1, 2.5f, -3}));
        EXPECT_EQ(got[1], (std::vector<float>{0.25f}));
        EXPECT_EQ(got[2], (std::vector<float>{7, 8}));
        EXPECT_EQ(viewer::read_point_values(dir.file("a.tsf"), {3, 1, 2}, false),
                  (std::vector<float>{1, 2.5f, -3, 0.25f, 7, 8}));
    }
}

TEST(ViewerPointValues, RejectsMalformedAndMismatchedFiles) {
    const TempDir dir;
    const std::vector<std::vector<double>> tracks{{1, 2, 3}, {4, 5}};
    write_file(dir.file("ok.tsf"), tsf_bytes(tracks));
    // Counts: streamlines, then points of one streamline.
    EXPECT_EQ(error_of([&] { viewer::read_point_values(dir.file("ok.tsf"), {3, 2, 1}, false); }), Errc::invalid_input);
    EXPECT_EQ(error_of([&] { viewer::read_point_values(dir.file("ok.tsf"), {3, 3}, false); }), Errc::invalid_input);
    try {
        viewer::read_point_values(dir.file("ok.tsf"), {3, 3}, true);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("streamline 1 has 2 values for 3 points"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("resampled"), std::string::npos) << e.what();
    }
    // No Inf at the end (as tcksample writes them): read; a streamline without its NaN: truncated.
    write_file(dir.file("a.tsf"), tsf_bytes(tracks, "Float32LE", false));
    EXPECT_EQ(fiblet::read_track_scalars(dir.file("a.tsf")).size(), 2u);
    std::string cut = tsf_bytes(tracks, "Float32LE", false);
    write_file(dir.file("a.tsf"), cut.substr(0, cut.size() - 4));
    EXPECT_EQ(error_of([&] { fiblet::read_track_scalars(dir.file("a.tsf")); }), Errc::tck_format);
    // Malformed: unknown datatype, not a .tsf, no END, offset past the end, Inf inside a streamline.
    write_file(dir.file("b.tsf"), tsf_bytes(tracks, "Int32LE"));
    EXPECT_EQ(error_of([&] { fiblet::read_track_scalars(dir.file("b.tsf")); }), Errc::unsupported);
    std::string tck = tsf_bytes(tracks);
    tck.replace(0, 20, "mrtrix tracks       ");
    write_file(dir.file("c.tsf"), tck);
    EXPECT_EQ(error_of([&] { fiblet::read_track_scalars(dir.file("c.tsf")); }), Errc::tck_format);
    std::string no_end = tsf_bytes(tracks);
    no_end.replace(no_end.find("END"), 3, "XXX");
    write_file(dir.file("d.tsf"), no_end);
    EXPECT_EQ(error_of([&] { fiblet::read_track_scalars(dir.file("d.tsf")); }), Errc::tck_format);
    std::string far = tsf_bytes(tracks);
    far.replace(far.find(". 128"), 5, ". 999");
    write_file(dir.file("e.tsf"), far);
    EXPECT_EQ(error_of([&] { fiblet::read_track_scalars(dir.file("e.tsf")); }), Errc::tck_format);
    write_file(dir.file("f.tsf"), tsf_bytes({{1, std::numeric_limits<double>::infinity(), 2}}));
    EXPECT_EQ(error_of([&] { fiblet::read_track_scalars(dir.file("f.tsf")); }), Errc::tck_format);
    EXPECT_EQ(error_of([&] { fiblet::read_track_scalars(dir.file("missing.tsf")); }), Errc::io);
}

TEST(ViewerPointValues, ColormapsMatchMatplotlibsEnds) {
    using viewer::ColormapName;
    EXPECT_NEAR(viewer::colormap_color(ColormapName::viridis, 0)[0], 0.267f, 1e-3);
    EXPECT_NEAR(viewer::colormap_color(ColormapName::magma, 1)[2], 0.750f, 1e-3);
    EXPECT_NEAR(viewer::colormap_color(ColormapName::coolwarm, 0.5f)[1], 0.864f, 1e-3);
    EXPECT_EQ(viewer::colormap_color(ColormapName::magma, 2), viewer::colormap_color(ColormapName::magma, 1));
    EXPECT_EQ(viewer::parse_colormap("coolwarm"), ColormapName::coolwarm);
    EXPECT_FALSE(viewer::parse_colormap("jet"));
}

// A straight fiber along x seen from +z, values rising with x: every drawn
// pixel shows the colour map at its own x, fine blocks and coarse alike.
TEST(ViewerPointValues, LinesShowTheColormapOfTheirPointsValues) {
    FIBLET_REQUIRE_GL();
    CompressedScene compressed({straight_fiber()});
    viewer::GpuScene& scene = compressed.scene;
    scene.set_point_values(x_values());
    EXPECT_THROW(scene.set_point_values({1, 2}), Error);
    const int w = 200, h = 64;
    const auto [cam, half_width_mm] = top_view(w, h);
    viewer::Renderer renderer(*viewer_gl().programs);
    viewer::RenderTarget target(w, h);
    for (const auto style : {viewer::DrawStyle::lines, viewer::DrawStyle::tubes, viewer::DrawStyle::capsules})
    for (const auto map : {viewer::ColormapName::viridis, viewer::ColormapName::magma, viewer::ColormapName::coolwarm})
        for (const bool coarse : {false, true}) {
            SCOPED_TRACE(std::string(viewer::draw_style_name(style)) + " " + viewer::colormap_name(map) +
                         (coarse ? " coarse" : " fine"));
            viewer::RenderOptions o;
            o.style = style;
            o.tube_radius_mm = 0.4f;
            o.lighting = false;
            o.point_values = true;
            o.colormap = map;
            o.value_range = std::array<float, 2>{-15, 15};  // clamped beyond
            o.level_of_detail = coarse;
            o.lod_pixels = coarse ? 1e6f : o.lod_pixels;
            renderer.render(scene, cam, o, target);
            const auto ids = target.read_fibers();
            const auto rgba = target.read_rgba();
            std::size_t drawn = 0, right = 0;
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    const std::size_t i = std::size_t(y) * w + std::size_t(x);
                    if (ids[i] == 0) continue;
                    ++drawn;
                    const float world_x = float(((x + 0.5) / w * 2 - 1) * half_width_mm);
                    const auto c = viewer::colormap_color(map, viewer::colormap_position(world_x, -15, 15));
                    bool same = true;
                    for (std::size_t k = 0; k < 3; ++k) same &= std::abs(int(rgba[4 * i + k]) - int(std::lround(c[k] * 255))) <= 4;
                    right += same;
                }
            EXPECT_GT(drawn, 70u);  // 40 mm at 2 pixels per mm
            EXPECT_EQ(right, drawn);
        }
}

// Transparent lines (sorted and unsorted blending) over a black background:
// the colour map at the pixel's x, times the opacity.
TEST(ViewerPointValues, TransparentLinesBlendTheColormapOfTheirValues) {
    FIBLET_REQUIRE_GL();
    CompressedScene compressed({straight_fiber()});
    compressed.scene.set_point_values(x_values());
    const int w = 200, h = 64;
    const auto [cam, half_width_mm] = top_view(w, h);
    viewer::Renderer renderer(*viewer_gl().programs);
    viewer::RenderTarget target(w, h);
    for (const auto mode : {viewer::TransparencyMode::sorted, viewer::TransparencyMode::unsorted}) {
        viewer::RenderOptions o;
        o.lighting = false;
        o.point_values = true;
        o.color_bar = false;
        o.value_range = std::array<float, 2>{-15, 15};
        o.opacity = 0.5f;
        o.transparency = mode;
        o.background = {0, 0, 0};
        renderer.render(compressed.scene, cam, o, target);
        const auto rgba = target.read_rgba();
        std::size_t drawn = 0, right = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const std::size_t i = std::size_t(y) * w + std::size_t(x);
                if (rgba[4 * i] == 0 && rgba[4 * i + 1] == 0 && rgba[4 * i + 2] == 0) continue;
                ++drawn;
                const float world_x = float(((x + 0.5) / w * 2 - 1) * half_width_mm);
                const auto c = viewer::colormap_color(o.colormap, viewer::colormap_position(world_x, -15, 15));
                bool same = true;
                for (std::size_t k = 0; k < 3; ++k) same &= std::abs(int(rgba[4 * i + k]) - int(std::lround(c[k] * 0.5f * 255))) <= 4;
                right += same;
            }
        EXPECT_GT(drawn, 70u);
        EXPECT_EQ(right, drawn);
    }
}

TEST(ViewerPointValues, CommandLineRefusesMismatchedFiles) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string fft = compress_fibers(dir, {straight_fiber(), {{0, 5, 0}, {0.5f, 5, 0}, {1, 5, 0}}}, "two");
    ASSERT_FALSE(FftFile(fft).resampling());
    std::vector<double> ramp;
    for (int i = 0; i <= 80; ++i) ramp.push_back(i);
    write_file(dir.file("ok.tsf"), tsf_bytes({ramp, {1, 2, 3}}));
    write_file(dir.file("count.tsf"), tsf_bytes({ramp}));
    write_file(dir.file("points.tsf"), tsf_bytes({ramp, {1, 2}}));
    const std::string common = "render " + fft + " --size 64x48 -f -o " + dir.file("a.png") + " --point-values ";
    const CommandResult ok = run_cli(common + dir.file("ok.tsf") + " --colormap magma --value-range 0,80");
    EXPECT_EQ(ok.status, 0) << ok.output;
    const CommandResult no_bar = run_cli("render " + fft + " --size 64x48 -f -o " + dir.file("n.png") + " --point-values " +
                                         dir.file("ok.tsf") + " --colormap magma --value-range 0,80 --no-color-bar");
    EXPECT_EQ(no_bar.status, 0) << no_bar.output;
    EXPECT_NE(read_file(dir.file("a.png")), read_file(dir.file("n.png")));  // render's image has the bar
    const CommandResult count = run_cli(common + dir.file("count.tsf"));
    EXPECT_EQ(count.status, 4) << count.output;
    EXPECT_NE(count.output.find("1 streamlines for the .fft's 2"), std::string::npos) << count.output;
    const CommandResult points = run_cli(common + dir.file("points.tsf"));
    EXPECT_EQ(points.status, 4) << points.output;
    EXPECT_NE(points.output.find("streamline 1 has 2 values for 3 points"), std::string::npos) << points.output;
    const CommandResult data = run_cli(common + "dpv/nothing");
    EXPECT_EQ(data.status, 2) << data.output;
    EXPECT_NE(data.output.find("no per-point data dpv/nothing"), std::string::npos) << data.output;
    // Another spacing makes compress resample: the .tsf of the original points no longer fits.
    const std::string resampled = compress_fibers(dir, {straight_fiber(), {{0, 5, 0}, {1, 5, 0}, {2, 5, 0}}}, "rs");
    ASSERT_TRUE(FftFile(resampled).resampling());
    write_file(dir.file("rs.tsf"), tsf_bytes({ramp, {1, 2, 3}}));
    const CommandResult refused = run_cli("render " + resampled + " --size 64x48 -f -o " + dir.file("b.png") +
                                          " --point-values " + dir.file("rs.tsf"));
    EXPECT_EQ(refused.status, 4) << refused.output;
    EXPECT_NE(refused.output.find("resampled at compress time"), std::string::npos) << refused.output;
    for (const std::string& bad : {dir.file("ok.tsf") + " --colormap jet", dir.file("ok.tsf") + " --value-range 5,1",
                                   dir.file("ok.tsf") + " --fiber-values " + dir.file("ok.tsf")}) {
        const CommandResult r = run_cli(common + bad);
        EXPECT_EQ(r.status, 2) << bad << ": " << r.output;
    }
}

TEST(ViewerPointValues, ValuesFromTheFilesOwnPerPointData) {
    // complex.trk carries scalars (dpv/fa): through a .fft (resampled with
    // its points when compress resamples) they colour the render exactly as
    // the same numbers in a .tsf do.
    FIBLET_REQUIRE_GL();
    if (!shared_data_available()) GTEST_SKIP() << "no shared data";
    const TempDir dir;
    const std::string fft = dir.file("c.fft");
    const CommandResult made = run_cli("compress -q " + shared_data("conformance/complex.trk") + " -o " + fft);
    ASSERT_EQ(made.status, 0) << made.output;
    const FftFile file(fft);
    const viewer::GpuScene scene(file, *viewer_gl().programs);  // the points per fiber
    std::vector<std::vector<double>> tracks;
    for (const StreamlineField& f : file.streamline_fields())
        if (f.name == "dpv/fa") {
            std::uint64_t row = 0;
            for (std::uint64_t s = 0; s < file.header().fibers; ++s) {
                tracks.emplace_back();
                for (std::uint64_t k = 0; k < scene.fiber_points(s); ++k) tracks.back().push_back(float(f.at(row++, 0)));
            }
        }
    ASSERT_FALSE(tracks.empty()) << "complex.trk lost its scalars";
    write_file(dir.file("fa.tsf"), tsf_bytes(tracks));
    const std::string common = "render " + fft + " --size 96x64 --no-lighting --colormap coolwarm --point-values ";
    const CommandResult from_data = run_cli(common + "dpv/fa -o " + dir.file("data.png"));
    ASSERT_EQ(from_data.status, 0) << from_data.output;
    const CommandResult from_tsf = run_cli(common + dir.file("fa.tsf") + " -o " + dir.file("tsf.png"));
    ASSERT_EQ(from_tsf.status, 0) << from_tsf.output;
    EXPECT_EQ(read_file(dir.file("data.png")), read_file(dir.file("tsf.png")));
    const CommandResult plain = run_cli("render " + fft + " --size 96x64 --no-lighting -o " + dir.file("plain.png"));
    ASSERT_EQ(plain.status, 0) << plain.output;
    EXPECT_NE(read_file(dir.file("data.png")), read_file(dir.file("plain.png")));  // the values did colour it
    const CommandResult colors = run_cli(common + "dpv/colors -o " + dir.file("m.png"));
    EXPECT_EQ(colors.status, 4) << colors.output;
    EXPECT_NE(colors.output.find("3 values per point"), std::string::npos) << colors.output;
}

TEST(ViewerPointValues, ColourBarLabelsPutTheNameBetweenTheEnds) {
    EXPECT_EQ(viewer::color_bar_labels(0, 1, "fa", 20), "0        fa        1");
    EXPECT_EQ(viewer::color_bar_labels(-0.5f, 1200, "a_very_long_name", 20), "-0.5         1.2e+03");
    EXPECT_EQ(viewer::glyph_bits('0'), 0b111101101101111u);
    EXPECT_EQ(viewer::glyph_bits('A'), viewer::glyph_bits('a'));
    EXPECT_EQ(viewer::glyph_bits('#'), 0u);
}

// The bar at the bottom edge: the colour map across its gradient (a CPU
// colouring of t at each pixel's centre), the glyphs of its labels under
// it, and no fiber where it lies.
TEST(ViewerPointValues, ColourBarShowsTheMapAndItsRange) {
    FIBLET_REQUIRE_GL();
    CompressedScene compressed({straight_fiber()});
    compressed.scene.set_point_values(x_values());
    const int w = 256, h = 128;
    viewer::Renderer renderer(*viewer_gl().programs);
    viewer::RenderTarget target(w, h);
    const Camera cam = viewer::camera_from_spec("top", compressed.scene, float(w) / float(h), 35, 1);
    viewer::RenderOptions o;
    o.point_values = true;
    o.colormap = viewer::ColormapName::magma;
    o.value_range = std::array<float, 2>{0, 1};
    o.value_name = "fa";
    renderer.render(compressed.scene, cam, o, target);
    const auto rgba = target.read_rgba();
    const auto ids = target.read_fibers();
    const viewer::ColorBarLayout l = viewer::color_bar_layout(w, h);
    ASSERT_GE(l.cells, 8);
    auto at = [&](int x, int y_up) { return std::size_t(h - 1 - y_up) * w + std::size_t(x); };  // GL rows from the bottom
    const int gy = int((l.gradient[1] + l.gradient[3]) / 2);
    int checked = 0;
    for (int x = int(l.gradient[0]); x < int(l.gradient[2]); ++x) {
        const float t = (float(x) + 0.5f - l.gradient[0]) / (l.gradient[2] - l.gradient[0]);
        const auto c = viewer::colormap_color(o.colormap, t);
        for (std::size_t k = 0; k < 3; ++k)
            EXPECT_NEAR(int(rgba[4 * at(x, gy) + k]), int(std::lround(c[k] * 255)), 3) << x;
        EXPECT_EQ(ids[at(x, gy)], 0u);
        ++checked;
    }
    EXPECT_GT(checked, 100);
    // The first label cell is "0", the last "1": their glyphs pixel by pixel.
    const std::string labels = viewer::color_bar_labels(0, 1, "fa", l.cells);
    const int s = int(l.scale);
    for (const int cell : {0, l.cells - 1}) {
        const std::uint32_t bits = viewer::glyph_bits(labels[std::size_t(cell)]);
        ASSERT_NE(bits, 0u);
        for (int r = 0; r < 5; ++r)
            for (int c = 0; c < 3; ++c) {
                const int x = int(l.box[0]) + (4 * cell + c) * s, y = int(l.box[1]) + (5 - r) * s;
                const bool lit = (bits >> (14 - (3 * r + c))) & 1u;
                EXPECT_EQ(int(rgba[4 * at(x, y)]), lit ? 255 : 0) << "cell " << cell << " row " << r << " column " << c;
            }
    }
    // Off: the frame without the bar is another image.
    o.color_bar = false;
    renderer.render(compressed.scene, cam, o, target);
    EXPECT_NE(target.read_rgba(), rgba);
}
