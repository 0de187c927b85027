// Exit codes and messages name the real cause (issue 12, class 8).
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "cli_runner.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

using namespace fiblet;
namespace fs = std::filesystem;

namespace {

bool mentions(const test::CommandResult& r, const std::string& text) {
    return r.output.find(text) != std::string::npos;
}

// Fibers long enough for several zstd frames.
void write_tck(const std::string& path) {
    TckWriter w(path, {}, true);
    std::vector<Vec3f> f(500);
    for (int i = 0; i < 200; ++i) {
        for (std::size_t k = 0; k < f.size(); ++k)
            f[k] = {0.1f * float(k), float(i % 20) + 0.01f * float(k % 7), 0.02f * float((k * i) % 31)};
        w.write(f);
    }
    w.finish();
}

}  // namespace

TEST(CliMessages, AbsurdThreadCountsAreUsageErrors) {
    test::TempDir dir;
    test::write_three_fiber_tck(dir.file("in.tck"));
    ASSERT_EQ(test::run_cli("compress -q " + dir.file("in.tck") + " -o " + dir.file("in.fft")).status, 0);
    for (const std::string& args : {"compress -q -j 4294967295 " + dir.file("in.tck") + " -o " + dir.file("b.fft"),
                                    "decompress -q -j 4294967295 " + dir.file("in.fft") + " -o " + dir.file("b.tck"),
                                    "decompress -q -j 1025 " + dir.file("in.fft") + " -o " + dir.file("b.tck")}) {
        const auto r = test::run_cli(args);
        EXPECT_EQ(r.status, 2) << args << "\n" << r.output;
        EXPECT_TRUE(mentions(r, "at most 1024")) << r.output;
    }
    EXPECT_EQ(test::run_cli("decompress -q -j 1024 " + dir.file("in.fft") + " -o " + dir.file("b.tck")).status, 0);
}

TEST(CliMessages, SelectionsThatCannotMeanWhatWasTypedAreUsageErrors) {
    test::TempDir dir;
    test::write_three_fiber_tck(dir.file("in.tck"));
    ASSERT_EQ(test::run_cli("compress -q " + dir.file("in.tck") + " -o " + dir.file("in.fft")).status, 0);
    const std::string base = "extract -q " + dir.file("in.fft") + " -o " + dir.file("out.tck") + " ";
    // (A box's corners may come in either order: the CLI orders them, so no box is inverted.)
    for (const std::string& sel : {std::string("--fibers ''"), std::string("--fibers=''"), std::string("--fibers 0,"),
                                   std::string("--fibers 5-2"), std::string("--include 1,1,1,-1"),
                                   std::string("--include 1,1,1")}) {
        const auto r = test::run_cli(base + sel);
        EXPECT_EQ(r.status, 2) << sel << "\n" << r.output;
    }
    EXPECT_FALSE(fs::exists(dir.file("out.tck")));
    EXPECT_EQ(test::run_cli(base + "--include 0,0,0,8,2,3").status, 0);
}

TEST(CliMessages, APipeAsInputIsNamedAsSuch) {
    test::TempDir dir;
    test::write_three_fiber_tck(dir.file("in.tck"));
    ASSERT_EQ(test::run_cli("compress -q " + dir.file("in.tck") + " -o " + dir.file("in.fft")).status, 0);
    for (const std::string& cmd : {"cat " + dir.file("in.tck") + " | " + FIBLET_CLI + " compress -q /dev/stdin -o " +
                                       dir.file("out.fft") + " 2>&1",
                                   "cat " + dir.file("in.fft") + " | " + FIBLET_CLI + " decompress -q /dev/stdin -o " +
                                       dir.file("out.tck") + " 2>&1"}) {
        const auto r = test::run_command(cmd);
        EXPECT_EQ(r.status, 3) << cmd << "\n" << r.output;
        EXPECT_TRUE(mentions(r, "not a regular file")) << r.output;
        EXPECT_FALSE(mentions(r, "data offset")) << r.output;
    }
}

TEST(CliMessages, AnEmptyHeaderKeyRoundTrips) {
    test::TempDir dir;
    {
        TckWriter w(dir.file("in.tck"), {{"", "anonymous value"}, {"kept", "yes"}}, true);
        w.write(std::vector<Vec3f>{{0, 0, 0}, {0.1f, 0, 0}, {0.2f, 0, 0}});
        w.finish();
    }
    ASSERT_EQ(read_tck_header(dir.file("in.tck")).get(""), std::optional<std::string>("anonymous value"));
    EXPECT_EQ(test::run_cli("compress -q " + dir.file("in.tck") + " -o " + dir.file("in.fft")).status, 0);
    EXPECT_EQ(test::run_cli("verify -q " + dir.file("in.fft")).status, 0);
    const auto r = test::run_cli("decompress -q " + dir.file("in.fft") + " -o " + dir.file("out.tck"));
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(read_tck_header(dir.file("out.tck")).get(""), std::optional<std::string>("anonymous value"));
}

TEST(CliMessages, CorruptionInsideAZstdFrameIsAnIntegrityFailure) {
    test::TempDir dir;
    write_tck(dir.file("in.tck"));
    ASSERT_EQ(test::run_cli("compress -q -z --zstd-group 64 " + dir.file("in.tck") + " -o " + dir.file("in.fftz")).status,
              0);
    std::string bytes = test::read_file(dir.file("in.fftz"));
    // The middle of the file: block-group frames, far from the header frames and the seek table.
    for (std::size_t at : {bytes.size() / 2, bytes.size() / 3}) {
        std::string damaged = bytes;
        damaged[at] = char(damaged[at] ^ 0x10);
        test::write_file(dir.file("bad.fftz"), damaged);
        for (const std::string& args : {"verify -q " + dir.file("bad.fftz"),
                                        "decompress -q -f " + dir.file("bad.fftz") + " -o " + dir.file("bad.tck")}) {
            const auto r = test::run_cli(args);
            EXPECT_EQ(r.status, 7) << args << " (byte " << at << ")\n" << r.output;
        }
    }
}

TEST(CliMessages, StreamlinesAreCountedFromZeroEverywhere) {
    test::TempDir dir;
    test::write_three_fiber_tck(dir.file("in.tck"));
    std::string bytes = test::read_file(dir.file("in.tck"));
    bytes.resize(bytes.size() - 20);  // cuts the last streamline (index 2) mid-point
    test::write_file(dir.file("cut.tck"), bytes);
    const auto r = test::run_cli("compress -q --allow-count-mismatch " + dir.file("cut.tck") + " -o " + dir.file("c.fft"));
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(mentions(r, "(0-based)")) << r.output;
    EXPECT_FALSE(mentions(r, "counting from 1")) << r.output;
}

TEST(CliMessages, ANonFiniteDecodeBlamesTheInput) {
    test::TempDir dir;
    test::write_three_fiber_tck(dir.file("in.tck"));
    ASSERT_EQ(test::run_cli("compress -q --no-index " + dir.file("in.tck") + " -o " + dir.file("in.fft")).status, 0);
    // A file as the official encoder writes it (no trailer, so no checksum to
    // stop it), whose scaling and offset are finite but overflow once combined.
    std::string bytes = test::read_file(dir.file("in.fft"));
    bytes.resize(FftFile(dir.file("in.fft")).header().file_bytes());
    const float huge = 3e38f;
    for (std::size_t off : {25, 29, 33, 37}) std::memcpy(&bytes[off], &huge, 4);  // scaling, offset x, y, z
    test::write_file(dir.file("hostile.fft"), bytes);
    const auto r = test::run_cli("decompress -q " + dir.file("hostile.fft") + " -o " + dir.file("out.tck"));
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_TRUE(mentions(r, dir.file("hostile.fft") + ": fiber 0 (0-based) decodes to a non-finite")) << r.output;
    EXPECT_FALSE(mentions(r, "out.tck")) << r.output;
    EXPECT_FALSE(fs::exists(dir.file("out.tck")));
}

TEST(CliMessages, AFlippedChecksumAlgorithmIsAnIntegrityFailure) {
    test::TempDir dir;
    test::write_three_fiber_tck(dir.file("in.tck"));
    ASSERT_EQ(test::run_cli("compress -q " + dir.file("in.tck") + " -o " + dir.file("in.fft")).status, 0);
    const std::string bytes = test::read_file(dir.file("in.fft"));
    const std::size_t tag = bytes.rfind("CSUM");
    ASSERT_NE(tag, std::string::npos);
    for (unsigned char bit : {0x01, 0x02, 0x80}) {  // the algorithm's low byte: 1 (XXH64) becomes 0, 3, 129
        std::string damaged = bytes;
        damaged[tag + 16] = char(damaged[tag + 16] ^ bit);
        test::write_file(dir.file("bad.fft"), damaged);
        for (const std::string cmd : {"verify -q ", "info "}) {
            const auto r = test::run_cli(cmd + dir.file("bad.fft"));
            EXPECT_EQ(r.status, 7) << cmd << int(bit) << "\n" << r.output;
        }
    }
}

// Sparse, unevenly spaced input (0.2 mm segments, then 20 mm ones) is
// resampled to the fine step: the .fft grows past the input, and compress
// says so and which --step keeps about the input's points. The report's
// Hausdorff distance stays at the point error (it once read 61 mm: the
// metric's window did not reach along the resampled polyline).
TEST(CliMessages, AnOutputLargerThanItsSparseInputIsExplained) {
    const test::TempDir dir;
    {
        TckWriter w(dir.file("sparse.tck"), {}, true);
        for (int i = 0; i < 50; ++i) {
            std::vector<Vec3f> f;
            for (int k = 0; k < 16; ++k) f.push_back({0.2f * float(k), float(i), std::sin(0.02f * float(k))});
            for (int k = 1; k <= 4; ++k) f.push_back({3.0f + 20.0f * float(k), float(i), std::sin(0.3f * float(k))});
            w.write(f);
        }
        w.finish();
    }
    const auto r = test::run_cli("compress --json " + dir.file("sparse.tck") + " -o " + dir.file("sparse.fft"));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_GT(fs::file_size(dir.file("sparse.fft")), fs::file_size(dir.file("sparse.tck")));
    EXPECT_TRUE(mentions(r, "is larger than " + dir.file("sparse.tck"))) << r.output;
    EXPECT_TRUE(mentions(r, "its 1000 points were resampled to")) << r.output;
    EXPECT_TRUE(mentions(r, "keeps about the input's point count")) << r.output;
    const std::size_t at = r.output.find("\"hausdorff_um\": ");
    ASSERT_NE(at, std::string::npos) << r.output;
    EXPECT_LT(std::stod(r.output.substr(at + 16)), 50.0) << r.output;
    // An input the .fft is smaller than: no note.
    const auto dense = test::run_cli("compress -f " + test::shared_data("bundles/CST_R.tck") + " -o " + dir.file("cst.fft"));
    EXPECT_EQ(dense.status, 0);
    EXPECT_FALSE(mentions(dense, "is larger than")) << dense.output;
}
