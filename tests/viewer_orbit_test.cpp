// Turntable frames (render --orbit): the camera turned about its up axis,
// and the numbered PNGs the command writes.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "cli_runner.hpp"
#include "window/orbit_camera.hpp"
#include "gl/png_file.hpp"
#include "viewer_test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;

namespace {
float distance(Vec3f a, Vec3f b) { return std::hypot(a.x - b.x, a.y - b.y, a.z - b.z); }
}  // namespace

TEST(ViewerOrbit, TurnsTheEyeAboutTheUpAxisThroughTheTarget) {
    Camera c;
    c.position = {1, 2, 13}, c.target = {1, 2, 3}, c.up = {0, 1, 0};
    const viewer::SceneBounds bounds;  // [-1, 1]³
    // Right-handed: +z turned 90° about +y is +x.
    const Camera quarter = viewer::turned_about_up(c, 90, bounds);
    EXPECT_LT(distance(quarter.position, {11, 2, 3}), 1e-4f);
    EXPECT_EQ(quarter.target.x, c.target.x);
    EXPECT_EQ(quarter.up.y, c.up.y);
    EXPECT_LT(distance(viewer::turned_about_up(c, 360, bounds).position, c.position), 1e-4f);
    const Camera unchanged = viewer::turned_about_up(c, 0, bounds);
    EXPECT_EQ(unchanged.position.z, c.position.z);
    EXPECT_EQ(unchanged.near_mm, c.near_mm);
    // An up vector not orthogonal to the view: the distance to the target and
    // the height along up are kept.
    c.up = {0, 0.6f, 0.8f};
    for (const float deg : {37.0f, 180.0f, 291.0f}) {
        const Camera t = viewer::turned_about_up(c, deg, bounds);
        EXPECT_NEAR(distance(t.position, c.target), 10.0f, 1e-4f) << deg;
        const auto height = [&](Vec3f p) { return 0.6f * (p.y - c.target.y) + 0.8f * (p.z - c.target.z); };
        EXPECT_NEAR(height(t.position), height(c.position), 1e-4f) << deg;
    }
}

TEST(ViewerOrbit, RenderWritesNumberedFramesStartingAtThePlainView) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string fft = compress_into(dir, shared_data("bundles/AF_L.tck"), "af.fft");
    const std::string common = "render " + fft + " --size 64x48 --camera left";
    ASSERT_EQ(run_cli(common + " -o " + dir.file("plain.png")).status, 0);
    const CommandResult r = run_cli(common + " --orbit 4 -o " + dir.file("turn.png"));
    ASSERT_EQ(r.status, 0) << r.output;
    for (const char* name : {"turn-000.png", "turn-001.png", "turn-002.png", "turn-003.png"})
        EXPECT_TRUE(std::filesystem::exists(dir.file(name))) << name;
    EXPECT_FALSE(std::filesystem::exists(dir.file("turn-004.png")));
    EXPECT_FALSE(std::filesystem::exists(dir.file("turn.png")));
    EXPECT_EQ(viewer::read_png(dir.file("turn-000.png")).rgba, viewer::read_png(dir.file("plain.png")).rgba);
    EXPECT_NE(viewer::read_png(dir.file("turn-001.png")).rgba, viewer::read_png(dir.file("plain.png")).rgba);
    // Existing frames are not overwritten without --force; nothing is written.
    std::filesystem::remove(dir.file("turn-000.png"));
    const CommandResult again = run_cli(common + " --orbit 4 -o " + dir.file("turn.png"));
    EXPECT_EQ(again.status, 5) << again.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("turn-000.png")));
    EXPECT_EQ(run_cli(common + " --orbit -2 -o " + dir.file("x.png")).status, 2);
}

TEST(ViewerOrbit, CameraPathFileGivesOneFramePerCamera) {
    FIBLET_REQUIRE_GL();
    const TempDir dir;
    const std::string fft = compress_into(dir, shared_data("bundles/AF_L.tck"), "af.fft");
    const std::string common = "render " + fft + " --size 64x48";
    ASSERT_EQ(run_cli(common + " --camera left -o " + dir.file("left.png")).status, 0);
    ASSERT_EQ(run_cli(common + " --camera top -o " + dir.file("top.png")).status, 0);
    write_file(dir.file("path.txt"), "# a two-frame path\nleft\n\n  top  \n");
    const CommandResult r = run_cli(common + " --camera-path " + dir.file("path.txt") + " -o " + dir.file("p.png"));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(viewer::read_png(dir.file("p-000.png")).rgba, viewer::read_png(dir.file("left.png")).rgba);
    EXPECT_EQ(viewer::read_png(dir.file("p-001.png")).rgba, viewer::read_png(dir.file("top.png")).rgba);
    EXPECT_FALSE(std::filesystem::exists(dir.file("p-002.png")));
    // A bad camera anywhere in the path: nothing written.
    write_file(dir.file("bad.txt"), "left\nsideways\n");
    const CommandResult bad = run_cli(common + " --camera-path " + dir.file("bad.txt") + " -o " + dir.file("b.png"));
    EXPECT_EQ(bad.status, 2) << bad.output;
    EXPECT_FALSE(std::filesystem::exists(dir.file("b-000.png")));
    write_file(dir.file("empty.txt"), "# nothing\n");
    EXPECT_EQ(run_cli(common + " --camera-path " + dir.file("empty.txt") + " -o " + dir.file("e.png")).status, 2);
    EXPECT_EQ(run_cli(common + " --camera-path " + dir.file("path.txt") + " --orbit 3 -o " + dir.file("e.png")).status, 2);
}
