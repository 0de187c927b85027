// Per-fiber colours: the text files (colours, values through viridis) and
// renders where every pixel shows its own fiber's colour; the command
// line's checks of the per-fiber files (colours, values, radii).
#include <gtest/gtest.h>

#include <fmt/core.h>

#include <cstdlib>

#include "cli_runner.hpp"
#include "scene/fiber_colors.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/streamline_field.hpp"
#include "scene/gpu_scene.hpp"
#include "window/orbit_camera.hpp"
#include "render/render_target.hpp"
#include "render/renderer.hpp"
#include "viewer_test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;

TEST(ViewerFiberColors, ReadsOneEntryPerStreamline) {
    const TempDir dir;
    write_file(dir.file("c.txt"), "# colours\nff0000\n00ff80  0000ff\n\n");
    const auto c = viewer::read_fiber_colors(dir.file("c.txt"), 3);
    ASSERT_EQ(c.size(), 3u);
    EXPECT_EQ(c[0], (viewer::Rgb{1, 0, 0}));
    EXPECT_EQ(c[1], (viewer::Rgb{0, 1, 128.0f / 255.0f}));
    EXPECT_EQ(c[2], (viewer::Rgb{0, 0, 1}));
    auto category = [](auto&& f) {
        try {
            f();
        } catch (const Error& e) {
            return e.code();
        }
        return Errc::interrupted;  // nothing thrown
    };
    EXPECT_EQ(category([&] { viewer::read_fiber_colors(dir.file("c.txt"), 4); }), Errc::invalid_input);
    write_file(dir.file("bad.txt"), "ff0000\nred\n");
    EXPECT_EQ(category([&] { viewer::read_fiber_colors(dir.file("bad.txt"), 2); }), Errc::invalid_input);
    EXPECT_EQ(category([&] { viewer::read_fiber_colors(dir.file("missing.txt"), 2); }), Errc::io);

    write_file(dir.file("v.txt"), "# tcksift2-style weights, all on one line\n0.5 2 1.25 -1e-1\n");
    EXPECT_EQ(viewer::read_fiber_values(dir.file("v.txt"), 4), (std::vector<float>{0.5f, 2, 1.25f, -0.1f}));
    write_file(dir.file("nan.txt"), "1 nan\n");
    EXPECT_EQ(category([&] { viewer::read_fiber_values(dir.file("nan.txt"), 2); }), Errc::invalid_input);
}

TEST(ViewerFiberColors, ValuesMapThroughViridisOverTheirRange) {
    const auto c = viewer::colors_from_values({10, 20, 15, 30});
    EXPECT_EQ(c[0], viewer::viridis(0));
    EXPECT_EQ(c[3], viewer::viridis(1));
    // matplotlib's viridis ends: dark purple, yellow.
    EXPECT_NEAR(c[0][0], 0.267, 1e-3);
    EXPECT_NEAR(c[3][1], 0.906, 1e-3);
    EXPECT_EQ(c[1], viewer::viridis(0.5f));
    // Green grows monotonically along viridis.
    for (int i = 0; i < 100; ++i) EXPECT_LT(viewer::viridis(i / 100.0f)[1], viewer::viridis((i + 1) / 100.0f)[1]);
    const auto clamped = viewer::colors_from_values({-5, 5, 50}, std::array<float, 2>{0, 10});
    EXPECT_EQ(clamped[0], viewer::viridis(0));
    EXPECT_EQ(clamped[1], viewer::viridis(0.5f));
    EXPECT_EQ(clamped[2], viewer::viridis(1));
}

TEST(ViewerFiberColors, EveryPixelShowsItsFibersColour) {
    FIBLET_REQUIRE_GL();
    CompressedScene compressed(shared_data("bundles/AF_L-step0.1.tck"));
    viewer::GpuScene& scene = compressed.scene;
    // A distinct colour per fiber.
    std::vector<viewer::Rgb> colors;
    for (std::uint64_t f = 0; f < scene.fiber_count(); ++f)
        colors.push_back({float((f * 37) % 256) / 255.0f, float((f * 91 + 40) % 256) / 255.0f, float((255 - f * 13) % 256) / 255.0f});
    scene.set_fiber_colors(colors);
    viewer::Renderer renderer(*viewer_gl().programs);
    const int w = 128, h = 96;
    viewer::RenderTarget target(w, h);
    const Camera cam = viewer::camera_from_spec("left", scene, float(w) / float(h), 35, 1);
    for (const auto style : {viewer::DrawStyle::lines, viewer::DrawStyle::tubes, viewer::DrawStyle::capsules}) {
        SCOPED_TRACE(viewer::draw_style_name(style));
        viewer::RenderOptions o;
        o.style = style;
        o.lighting = false;
        o.fiber_colors = true;
        o.tube_radius_mm = 0.4f;
        renderer.render(scene, cam, o, target);
        const auto ids = target.read_fibers();
        const auto rgba = target.read_rgba();
        std::size_t drawn = 0, right = 0;
        for (std::size_t i = 0; i < ids.size(); ++i) {
            if (ids[i] == 0) continue;
            ++drawn;
            const viewer::Rgb& c = colors[ids[i] - 1];
            bool same = true;
            for (int k = 0; k < 3; ++k) same &= std::abs(int(rgba[4 * i + std::size_t(k)]) - int(std::lround(c[std::size_t(k)] * 255))) <= 1;
            right += same;
        }
        EXPECT_GT(drawn, 300u);
        EXPECT_EQ(right, drawn);
    }
    EXPECT_THROW(scene.set_fiber_colors({{1, 0, 0}}), Error);
}

TEST(ViewerFiberColors, CommandLineChecksTheFiles) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string fft = compress_into(dir, shared_data("bundles/AF_L.tck"), "af.fft");
    const FftFile file(fft);
    std::string values;
    for (std::uint64_t f = 0; f < file.header().fibers; ++f) values += std::to_string(f) + "\n";
    write_file(dir.file("v.txt"), values);
    write_file(dir.file("short.txt"), "1\n2\n");
    const std::string common = "render " + fft + " --size 64x48 -o " + dir.file("a.png");
    const CommandResult ok = run_cli(common + " --fiber-values " + dir.file("v.txt") + " --value-range 0:10");
    EXPECT_EQ(ok.status, 0) << ok.output;
    const CommandResult count = run_cli(common + " -f --fiber-values " + dir.file("short.txt"));
    EXPECT_EQ(count.status, 4) << count.output;
    EXPECT_NE(count.output.find("streamlines"), std::string::npos) << count.output;
    // Radii: one positive number per streamline.
    std::string radii;
    for (std::uint64_t f = 0; f < file.header().fibers; ++f) radii += "0.3\n";
    write_file(dir.file("r.txt"), radii);
    const CommandResult tubes = run_cli(common + " -f --style tubes --fiber-radii " + dir.file("r.txt"));
    EXPECT_EQ(tubes.status, 0) << tubes.output;
    const CommandResult zero = run_cli(common + " -f --style tubes --fiber-radii " + dir.file("v.txt"));  // 0, 1, ...
    EXPECT_EQ(zero.status, 4) << zero.output;
    EXPECT_NE(zero.output.find("not positive"), std::string::npos) << zero.output;
    for (const std::string& bad : {" --fiber-values " + dir.file("v.txt") + " --fiber-colors " + dir.file("v.txt"),
                                  std::string(" --value-range 0:10"),
                                  " --fiber-values " + dir.file("v.txt") + " --value-range 5:1"}) {
        const CommandResult r = run_cli(common + " -f" + bad);
        EXPECT_EQ(r.status, 2) << bad << ": " << r.output;
    }
}

TEST(ViewerFiberColors, ValuesFromTheFilesOwnPerStreamlineData) {
    // complex.trk carries properties (mean_curvature, ...): through a .fft
    // they colour the render exactly as the same numbers in a text file do.
    FIBLET_REQUIRE_GL();
    if (!shared_data_available()) GTEST_SKIP() << "no shared data";
    const TempDir dir;
    const std::string fft = dir.file("c.fft");
    const CommandResult made = run_cli("compress -q " + shared_data("conformance/complex.trk") + " -o " + fft);
    ASSERT_EQ(made.status, 0) << made.output;
    const FftFile file(fft);
    std::string values;
    for (const StreamlineField& f : file.streamline_fields())
        if (f.name == "dps/mean_curvature")
            for (std::uint64_t r = 0; r < f.rows(); ++r) values += fmt::format("{:.9g}\n", f.at(r, 0));
    ASSERT_FALSE(values.empty()) << "complex.trk lost its properties";
    write_file(dir.file("v.txt"), values);
    const std::string common = "render " + fft + " --size 64x48 --fiber-values ";
    const CommandResult from_data = run_cli(common + "dps/mean_curvature -o " + dir.file("data.png"));
    ASSERT_EQ(from_data.status, 0) << from_data.output;
    const CommandResult from_text = run_cli(common + dir.file("v.txt") + " -o " + dir.file("text.png"));
    ASSERT_EQ(from_text.status, 0) << from_text.output;
    EXPECT_EQ(read_file(dir.file("data.png")), read_file(dir.file("text.png")));
    // A name the file does not carry: a usage error listing what it has.
    const CommandResult missing = run_cli(common + "dps/nothing -o " + dir.file("m.png"));
    EXPECT_EQ(missing.status, 2) << missing.output;
    EXPECT_NE(missing.output.find("dps/mean_torsion"), std::string::npos) << missing.output;
    // mean_colors has three values per streamline: not one colour-map value.
    EXPECT_EQ(run_cli(common + "dps/mean_colors -o " + dir.file("m.png")).status, 4);
}
