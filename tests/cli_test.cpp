// The fiblet CLI end to end: outputs, exit codes, refusal to overwrite, no
// output left behind on bad input.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "fiblet/fft_file.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

using namespace fiblet;
namespace fs = std::filesystem;

namespace {

struct CliResult {
    int code;
    std::string out;
};

CliResult cli(const std::string& args) {
    const std::string cmd = std::string(FIBLET_CLI) + " " + args + " 2>&1";
    FILE* p = ::popen(cmd.c_str(), "r");
    std::string out;
    std::array<char, 4096> buf{};
    while (std::size_t n = std::fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
    const int status = ::pclose(p);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), out};
}

std::vector<std::string> listing(const std::string& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace

TEST(Cli, CompressDecompressStatsInfo) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    const std::string in = test::shared_data("small-sdstream.tck");
    CliResult r = cli("compress " + in + " -o " + dir.file("a.fft"));
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("1000 fibers, 853199 points"), std::string::npos) << r.out;

    r = cli("stats " + dir.file("a.fft") + " --reference " + in + " --json");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("\"fibers\": 1000"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("\"max_um\""), std::string::npos);

    r = cli("decompress " + dir.file("a.fft") + " -o " + dir.file("b.tck"));
    ASSERT_EQ(r.code, 0) << r.out;
    TckReader back(dir.file("b.tck")), orig(in);
    std::vector<Vec3f> x, y;
    std::uint64_t n = 0;
    double worst = 0;
    while (orig.next(x)) {
        ASSERT_TRUE(back.next(y));
        ASSERT_EQ(x.size(), y.size());
        for (std::size_t i = 0; i < x.size(); ++i)
            worst = std::max(worst, double(std::hypot(x[i].x - y[i].x, x[i].y - y[i].y, x[i].z - y[i].z)));
        ++n;
    }
    EXPECT_FALSE(back.next(y));
    EXPECT_EQ(n, 1000u);
    const FftFile f(dir.file("a.fft"));
    EXPECT_NEAR(worst, f.header().max_error_mm, 1e-5);
    // The source properties travel through the .fft.
    EXPECT_EQ(back.header().get("method"), std::optional<std::string>("SDStream"));
    EXPECT_EQ(back.header().count(), std::optional<std::uint64_t>(1000));

    // MRtrix3 itself reads the decoded file, with the source's properties.
    if (std::system("command -v tckinfo >/dev/null 2>&1") == 0) {
        FILE* p = ::popen(("tckinfo " + dir.file("b.tck") + " 2>&1").c_str(), "r");
        std::string info;
        std::array<char, 4096> buf{};
        while (std::size_t k = std::fread(buf.data(), 1, buf.size(), p)) info.append(buf.data(), k);
        EXPECT_EQ(::pclose(p), 0) << info;
        EXPECT_NE(info.find("count:                0000001000"), std::string::npos) << info;
        EXPECT_NE(info.find("SDStream"), std::string::npos) << info;
        EXPECT_NE(info.find("step_size:            0.1"), std::string::npos) << info;
    }

    EXPECT_EQ(cli("info " + dir.file("a.fft")).code, 0);
    r = cli("info " + in + " --json");
    EXPECT_EQ(r.code, 0);
    EXPECT_NE(r.out.find("\"datatype\": \"Float32LE\""), std::string::npos) << r.out;
}

TEST(Cli, RefusesToOverwriteWithoutForce) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    test::write_file(dir.file("a.fft"), "precious");
    const std::string in = test::shared_data("dwi-small64d-ifod1.tck");
    EXPECT_EQ(cli("compress " + in + " -o " + dir.file("a.fft")).code, 5);
    EXPECT_EQ(test::read_file(dir.file("a.fft")), "precious");
    EXPECT_EQ(cli("compress -q " + in + " -o " + dir.file("a.fft") + " --force").code, 0);
    EXPECT_NE(test::read_file(dir.file("a.fft")), "precious");
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"a.fft"});
}

TEST(Cli, BadInputExitsNonZeroAndLeavesNoOutput) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    // Truncated in the middle of a point.
    const std::string good = test::read_file(test::shared_data("dwi-small64d-ifod1.tck"));
    test::write_file(dir.file("trunc.tck"), good.substr(0, good.size() - 17));
    struct Case {
        std::string input;
        int code;
    };
    for (const Case& c : {Case{test::shared_data("conformance/no_magic_number.tck"), 4},
                          Case{test::shared_data("conformance/no_header_end.tck"), 4}, Case{dir.file("trunc.tck"), 4},
                          Case{test::shared_data("conformance/matlab_nan.tck"), 4}}) {
        const CliResult r = cli("compress " + c.input + " -o " + dir.file("out.fft"));
        EXPECT_EQ(r.code, c.code) << c.input << "\n" << r.out;
        EXPECT_NE(r.out.find("error"), std::string::npos);
        EXPECT_FALSE(fs::exists(dir.file("out.fft"))) << c.input;
    }
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"trunc.tck"}) << "temporary files left behind";
    // A .tck given where a .fft is expected, and a reference that does not match.
    EXPECT_EQ(cli("decompress " + test::shared_data("conformance/simple.tck") + " -o " + dir.file("x.tck")).code, 4);
    EXPECT_FALSE(fs::exists(dir.file("x.tck")));
    EXPECT_EQ(cli("stats " + test::shared_data("reference/small-ifod1.fft") + " -r " +
                  test::shared_data("small-sdstream.tck"))
                  .code,
              4);
    EXPECT_EQ(cli("compress --step -1 " + test::shared_data("conformance/simple.tck") + " -o " + dir.file("y.fft")).code,
              2);
    EXPECT_EQ(cli("frobnicate").code, 2);
}

TEST(Cli, BatchCompressionIntoADirectory) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    const CliResult r = cli("compress -q " + test::shared_data("bundles/AF_L-step0.1.tck") + " " +
                      test::shared_data("bundles/CST_R-step0.1.tck") + " --output-dir " + dir.path());
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"AF_L-step0.1.fft", "CST_R-step0.1.fft"}));
}

TEST(Cli, VariableStepInputIsResampledAndMeasuredBothWays) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    const std::string in = test::shared_data("small-ifod2.tck");
    CliResult r = cli("compress " + in + " -o " + dir.file("v.fft") + " --json");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("\"resampled\": true"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("\"step_mm\": 0.5"), std::string::npos) << r.out;  // the header's step_size
    r = cli("stats " + dir.file("v.fft") + " -r " + in);
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("vs original polyline"), std::string::npos) << r.out;
    // --step overrides.
    r = cli("compress " + in + " -o " + dir.file("w.fft") + " --step 0.25 --json");
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("\"step_mm\": 0.25"), std::string::npos) << r.out;
}

TEST(Cli, EdgeCaseFilesRoundTrip) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    // No fibers; one fiber whose 253 points coincide (zero steps); 1-, 2-, 5-point fibers.
    for (const char* name : {"empty.tck", "multiline_header_field.tck", "simple.tck", "simple_big_endian.tck"}) {
        const std::string in = test::shared_data(std::string("conformance/") + name);
        const std::string out = dir.file(std::string(name) + ".fft");
        CliResult r = cli("compress -q " + in + " -o " + out);
        ASSERT_EQ(r.code, 0) << name << "\n" << r.out;
        r = cli("stats " + out + " -r " + in + " --json");
        ASSERT_EQ(r.code, 0) << name << "\n" << r.out;
        const FftFile f(out);
        const Streamlines s = decode_fibers(f, 0, f.header().fibers);
        for (float v : s.xyz) ASSERT_TRUE(std::isfinite(v)) << name;
    }
}
