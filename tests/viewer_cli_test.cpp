// `fiblet render` and `fiblet view` from the command line: outputs, exit
// codes, and a clear failure where there is no display.
#include <gtest/gtest.h>

#include <fmt/core.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "gl/png_file.hpp"
#include "viewer_test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;

namespace {

std::size_t lit_pixels(const viewer::RgbaImage& im) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < im.rgba.size(); i += 4) n += (im.rgba[i] | im.rgba[i + 1] | im.rgba[i + 2]) != 0;
    return n;
}

}  // namespace

TEST(ViewerCli, RenderWritesAPngOfTheRequestedSize) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string fft = compress_into(dir, shared_data("bundles/CST_R.tck"), "cst.fft");
    const CommandResult r = run_cli("render " + fft + " -o " + dir.file("a.png") + " --size 120x90 --camera front");
    ASSERT_EQ(r.status, 0) << r.output;
    const viewer::RgbaImage im = viewer::read_png(dir.file("a.png"));
    EXPECT_EQ(im.width, 120);
    EXPECT_EQ(im.height, 90);
    EXPECT_GT(lit_pixels(im), 200u);

    // A .tck is compressed on the fly; a white background and a fixed colour.
    const CommandResult t = run_cli("render " + shared_data("bundles/CST_R.tck") + " -o " + dir.file("b.png") +
                          " --size 120x90 --camera front --background white --color 2040c0 --no-lighting");
    ASSERT_EQ(t.status, 0) << t.output;
    const viewer::RgbaImage b = viewer::read_png(dir.file("b.png"));
    std::size_t fixed = 0, white = 0;
    for (std::size_t i = 0; i < b.rgba.size(); i += 4) {
        fixed += b.rgba[i] == 0x20 && b.rgba[i + 1] == 0x40 && b.rgba[i + 2] == 0xc0;
        white += b.rgba[i] == 255 && b.rgba[i + 1] == 255 && b.rgba[i + 2] == 255;
    }
    EXPECT_EQ(fixed + white, b.rgba.size() / 4);
    EXPECT_GT(fixed, 200u);
}

// Tubes (and capsules) a few pixels wide cover more of the image than one-pixel lines of the
// same fibers (their exact shape: viewer_tubes_test).
TEST(ViewerCli, RenderDrawsTubes) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string fft = compress_into(dir, shared_data("bundles/CST_R-step0.1.tck"), "cst.fft");
    std::size_t lit[3] = {};
    const char* styles[3] = {"--style lines", "--style tubes --radius 0.5", "--style capsules --radius 0.5"};
    for (int i = 0; i < 3; ++i) {
        const std::string png = dir.file(std::to_string(i) + ".png");
        const CommandResult r = run_cli("render " + fft + " -o " + png + " --size 160x120 --camera left --zoom 2 " + styles[i]);
        ASSERT_EQ(r.status, 0) << r.output;
        lit[i] = lit_pixels(viewer::read_png(png));
    }
    EXPECT_GT(lit[1], lit[0] * 6 / 5);  // measured: 1.31
    EXPECT_GT(lit[2], lit[0] * 6 / 5);
}

TEST(ViewerCli, RenderRefusesBadArgumentsAndExistingOutputs) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string fft = compress_into(dir, shared_data("bundles/AF_L.tck"), "af.fft");
    write_file(dir.file("old.png"), "keep");
    const CommandResult exists = run_cli("render " + fft + " -o " + dir.file("old.png") + " --size 32x32");
    EXPECT_EQ(exists.status, 5) << exists.output;
    EXPECT_EQ(read_file(dir.file("old.png")), "keep");
    for (const char* bad : {"--size 100by50", "--size 0x10", "--camera 1,2", "--camera sideways", "--color purple",
                            "--fov 0", "--fibers 9:3", "--line-width 0", "--style ribbons", "--radius 0",
                            "--radius -1", "--supersample 0", "--supersample 9"}) {
        const CommandResult r = run_cli("render " + fft + " -o " + dir.file("x.png") + " " + bad);
        EXPECT_EQ(r.status, 2) << bad << ": " << r.output;
        EXPECT_FALSE(std::filesystem::exists(dir.file("x.png"))) << bad;
    }
    const CommandResult no_output = run_cli("render " + fft);
    EXPECT_EQ(no_output.status, 2) << no_output.output;
    const CommandResult bad_file = run_cli("render " + shared_data("conformance/no_magic_number.tck") + " -o " + dir.file("x.png"));
    EXPECT_EQ(bad_file.status, 4) << bad_file.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("x.png")));
}

// 16-bit files (formats/fft16.md, version 17 .fft and version 16 .fftz) render
// as the 8-bit file of the same fibers does (pixel by pixel: viewer_sixteen_bit_test).
TEST(ViewerCli, RenderDrawsSixteenBitFiles) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string tck = shared_data("bundles/CST_R-step0.1.tck");
    const std::string narrow = compress_into(dir, tck, "cst.fft");
    const std::string args = " --size 160x120 --camera left --zoom 2 --no-lod";
    ASSERT_EQ(run_cli("render " + narrow + " -o " + dir.file("8.png") + args).status, 0);
    const std::size_t lit8 = lit_pixels(viewer::read_png(dir.file("8.png")));
    for (const char* out : {"cst16.fft", "cst16.fftz"}) {
        const std::string wide = dir.file(out);
        const std::string zstd = std::string(out).ends_with(".fftz") ? " --zstd" : "";
        ASSERT_EQ(run_cli("compress -q --bits 16" + zstd + " " + tck + " -o " + wide).status, 0);
        const CommandResult r = run_cli("render " + wide + " -o " + dir.file("16.png") + " -f" + args);
        ASSERT_EQ(r.status, 0) << r.output;
        const std::size_t lit16 = lit_pixels(viewer::read_png(dir.file("16.png")));
        EXPECT_GT(lit8, 500u);
        EXPECT_NEAR(double(lit16), double(lit8), 0.03 * double(lit8)) << out;
    }
}

TEST(ViewerCli, BenchPrintsEveryStageForEveryCase) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string fft = compress_into(dir, shared_data("bundles/AF_L.tck"), "af.fft");
    const CommandResult r = run_cli("render " + fft + " --bench --frames 1 --size 64x48 --json");
    ASSERT_EQ(r.status, 0) << r.output;
    for (const char* key : {"\"overview\"", "\"close-up\"", "\"far\"", "\"cull_ms\"", "\"decode_ms\"", "\"draw_ms\""})
        EXPECT_NE(r.output.find(key), std::string::npos) << key << " in " << r.output;
}

// render --json: the blocks the GPU selection tested, drew and skipped. A
// close-up skips what lies outside its frustum; a subset of fibers skips
// the others' blocks; without culling, LoD or a subset nothing is tested.
TEST(ViewerCli, RenderReportsBlocksTestedDrawnAndSkipped) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string fft = compress_into(dir, shared_data("bundles/CST_R-step0.1.tck"), "cst.fft");
    const auto frame = [&](const std::string& options) {
        const CommandResult r =
            run_cli("render " + fft + " -o " + dir.file("a.png") + " -f --size 96x72 --json " + options);
        EXPECT_EQ(r.status, 0) << r.output;
        return nlohmann::json::parse(r.output.substr(r.output.find('{')))["frame"];
    };
    const auto info = nlohmann::json::parse(run_cli("info --json " + fft).output);
    const std::uint64_t blocks = info["blocks"].get<std::uint64_t>();
    const auto check = [&](const nlohmann::json& f) {
        EXPECT_EQ(f["blocks_drawn"].get<std::uint64_t>(),
                  f["full_blocks"].get<std::uint64_t>() + f["coarse_blocks"].get<std::uint64_t>());
        EXPECT_EQ(f["blocks_drawn"].get<std::uint64_t>() + f["blocks_skipped"].get<std::uint64_t>(),
                  f["blocks_tested"].get<std::uint64_t>());
    };
    const auto whole = frame("--camera front");
    check(whole);
    EXPECT_EQ(whole["blocks_tested"], blocks);
    EXPECT_EQ(whole["blocks_skipped"], 0);
    const auto close = frame("--camera front --zoom 6");
    check(close);
    EXPECT_EQ(close["blocks_tested"], blocks);
    EXPECT_GT(close["blocks_skipped"].get<std::uint64_t>(), blocks / 4);
    const auto subset = frame("--camera front --fibers 0-9 --no-culling --no-lod");
    check(subset);
    EXPECT_GT(subset["blocks_skipped"].get<std::uint64_t>(), 0u);
    EXPECT_LT(subset["blocks_drawn"].get<std::uint64_t>(), blocks / 2);
    const auto everything = frame("--camera front --no-culling --no-lod");
    EXPECT_EQ(everything["blocks_tested"], 0);
    EXPECT_EQ(everything["blocks_drawn"], blocks);
}

// --gpu-memory below what the file takes: the close-up's fibers are held,
// within the budget, and draw the image of the whole file.
TEST(ViewerCli, RenderHoldsTheViewsFibersWithinGpuMemory) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    // 240 straight fibers 0.2 mm apart, seen from 12 mm above a fifth of them
    // (an explicit camera: named views are fitted to what is held first).
    std::vector<std::vector<Vec3f>> fibers(240);
    for (int k = 0; k < 240; ++k)
        for (int i = 0; i < 150; ++i) fibers[k].push_back({-10.0f + float(k % 5) + 0.1f * float(i), -24 + 0.2f * float(k), 0});
    const std::string fft = compress_fibers(dir, fibers, "parallel");
    const std::string camera = "-2,-12,12,-2,-12,0,0,1,0";
    const auto render = [&](const std::string& png, const std::string& options) {
        const CommandResult r = run_cli("render " + fft + " -o " + dir.file(png) +
                                        " -f --size 96x72 --json --camera " + camera + " " + options);
        EXPECT_EQ(r.status, 0) << r.output;
        return nlohmann::json::parse(r.output.substr(r.output.find('{')))["scene"];
    };
    const auto whole = render("whole.png", "");
    EXPECT_FALSE(whole["streamed"].get<bool>());
    EXPECT_EQ(whole["fibers_held"], whole["file_fibers"]);
    const double mib = double(whole["gpu_bytes"].get<std::uint64_t>()) / 1048576.0;
    const auto part = render("part.png", fmt::format("--gpu-memory {}", mib * 0.6));
    EXPECT_TRUE(part["streamed"].get<bool>());
    EXPECT_LT(part["fibers_held"].get<std::uint64_t>(), part["file_fibers"].get<std::uint64_t>());
    EXPECT_LE(double(part["gpu_bytes"].get<std::uint64_t>()), mib * 0.6 * 1048576.0);
    EXPECT_EQ(viewer::read_png(dir.file("part.png")).rgba, viewer::read_png(dir.file("whole.png")).rgba);
    EXPECT_NE(run_cli("render " + fft + " -o " + dir.file("x.png") + " --gpu-memory 0").status, 0);
}

TEST(ViewerCli, ViewWithoutADisplayFailsClearly) {
    const TempDir dir;
    const CommandResult r = run_cli("view " + shared_data("reference/small-sdstream.fft"),
                          "env -u DISPLAY -u WAYLAND_DISPLAY");
    EXPECT_EQ(r.status, 6) << r.output;  // unsupported
    EXPECT_NE(r.output.find("display"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("fiblet render"), std::string::npos) << r.output;
}

// A mistyped option of render or view is named, with the option meant,
// before the input is opened (here it does not even exist) or a window is
// asked for: exit 2, no image written.
TEST(ViewerCli, MistypedOptionsAreNamedBeforeAnythingElse) {
    const TempDir dir;
    const std::string missing = dir.file("missing.fft");
    const CommandResult render = run_cli("render " + missing + " -o " + dir.file("x.png") + " --stye tubes");
    EXPECT_EQ(render.status, 2) << render.output;
    EXPECT_NE(render.output.find("unknown option --stye (did you mean --style?); see fiblet render --help"),
              std::string::npos) << render.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("x.png")));
    const CommandResult view = run_cli("view " + missing + " --stye tubes", "env -u DISPLAY -u WAYLAND_DISPLAY");
    EXPECT_EQ(view.status, 2) << view.output;
    EXPECT_NE(view.output.find("unknown option --stye (did you mean --style?); see fiblet view --help"),
              std::string::npos) << view.output;
}
