// The fiblet CLI end to end: outputs, exit codes, refusal to overwrite, no
// output left behind on bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "fiblet/fft_file.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/tck.hpp"
#include "cli_runner.hpp"
#include "exact_error.hpp"
#include "test_util.hpp"

using namespace fiblet;
namespace fs = std::filesystem;
using fiblet::test::CommandResult;
using fiblet::test::run_cli;

namespace {

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
    CommandResult r = run_cli("compress " + in + " -o " + dir.file("a.fft"));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("1000 fibers, 853199 points"), std::string::npos) << r.output;

    r = run_cli("stats " + dir.file("a.fft") + " --reference " + in + " --json");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("\"fibers\": 1000"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("\"max_um\""), std::string::npos);

    r = run_cli("decompress " + dir.file("a.fft") + " -o " + dir.file("b.tck"));
    ASSERT_EQ(r.status, 0) << r.output;
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
    // The recorded max is that of the worse of the float decode (the .tck)
    // and the float64 reference decode, which may differ where a block's
    // walks diverge (docs/encode.md, "Decoder-independent error").
    const test::ExactMeasurement m = test::measure_exact(dir.file("a.fft"), in);
    EXPECT_LE(worst, m.header_max_mm + 1e-9);
    EXPECT_LE(m.exact.max_mm, m.header_max_mm + 1e-9);
    EXPECT_NEAR(std::max(worst, m.exact.max_mm), m.header_max_mm, 1e-5)
        << "float " << worst << ", float64 " << m.exact.max_mm << ", recorded " << m.header_max_mm;
    // The source properties travel through the .fft.
    EXPECT_EQ(back.header().get("method"), std::optional<std::string>("SDStream"));
    EXPECT_EQ(back.header().count(), std::optional<std::uint64_t>(1000));

    // MRtrix3 itself reads the decoded file, with the source's properties.
    if (std::system("command -v tckinfo >/dev/null 2>&1") == 0) {
        const CommandResult tckinfo = fiblet::test::run_command("tckinfo " + dir.file("b.tck") + " 2>&1");
        const std::string& info = tckinfo.output;
        EXPECT_EQ(tckinfo.status, 0) << info;
        EXPECT_NE(info.find("count:                0000001000"), std::string::npos) << info;
        EXPECT_NE(info.find("SDStream"), std::string::npos) << info;
        EXPECT_NE(info.find("step_size:            0.1"), std::string::npos) << info;
    }

    EXPECT_EQ(run_cli("info " + dir.file("a.fft")).status, 0);
    r = run_cli("info " + in + " --json");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.output.find("\"datatype\": \"Float32LE\""), std::string::npos) << r.output;
}

TEST(Cli, RefusesToOverwriteWithoutForce) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    test::write_file(dir.file("a.fft"), "precious");
    const std::string in = test::shared_data("dwi-small64d-ifod1.tck");
    EXPECT_EQ(run_cli("compress " + in + " -o " + dir.file("a.fft")).status, 5);
    EXPECT_EQ(test::read_file(dir.file("a.fft")), "precious");
    EXPECT_EQ(run_cli("compress -q " + in + " -o " + dir.file("a.fft") + " --force").status, 0);
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
        const CommandResult r = run_cli("compress " + c.input + " -o " + dir.file("out.fft"));
        EXPECT_EQ(r.status, c.code) << c.input << "\n" << r.output;
        EXPECT_NE(r.output.find("error"), std::string::npos);
        EXPECT_FALSE(fs::exists(dir.file("out.fft"))) << c.input;
    }
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"trunc.tck"}) << "temporary files left behind";
    // A .tck given where a .fft is expected (recognised, named, exit 6), and a reference that does not match.
    const CommandResult tck_for_fft =
        run_cli("decompress " + test::shared_data("conformance/simple.tck") + " -o " + dir.file("x.tck"));
    EXPECT_EQ(tck_for_fft.status, 6);
    EXPECT_NE(tck_for_fft.output.find("an MRtrix3 .tck tractogram, not a .fft file"), std::string::npos) << tck_for_fft.output;
    EXPECT_FALSE(fs::exists(dir.file("x.tck")));
    EXPECT_EQ(run_cli("stats " + test::shared_data("reference/small-ifod1.fft") + " -r " +
                  test::shared_data("small-sdstream.tck"))
                  .status,
              4);
    EXPECT_EQ(run_cli("compress --step -1 " + test::shared_data("conformance/simple.tck") + " -o " + dir.file("y.fft")).status,
              2);
    EXPECT_EQ(run_cli("frobnicate").status, 2);
}

TEST(Cli, BatchCompressionIntoADirectory) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    const CommandResult r = run_cli("compress -q " + test::shared_data("bundles/AF_L-step0.1.tck") + " " +
                      test::shared_data("bundles/CST_R-step0.1.tck") + " --output-dir " + dir.path());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"AF_L-step0.1.fft", "CST_R-step0.1.fft"}));
}

TEST(Cli, VariableStepInputIsResampledAndMeasuredBothWays) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    const std::string in = test::shared_data("small-ifod2.tck");
    CommandResult r = run_cli("compress " + in + " -o " + dir.file("v.fft") + " --json");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("\"resampled\": true"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("\"step_mm\": 0.5"), std::string::npos) << r.output;  // the header's step_size
    r = run_cli("stats " + dir.file("v.fft") + " -r " + in);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("decoded -> input"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("input -> decoded"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("endpoints moved"), std::string::npos) << r.output;
    r = run_cli("info " + dir.file("v.fft"));
    EXPECT_NE(r.output.find("fiber ends             kept (ENDS)"), std::string::npos) << r.output;
    // --step overrides.
    r = run_cli("compress " + in + " -o " + dir.file("w.fft") + " --step 0.25 --json");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("\"step_mm\": 0.25"), std::string::npos) << r.output;
}

TEST(Cli, EdgeCaseFilesRoundTrip) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    // No fibers; one fiber whose 253 points coincide (zero steps); 1-, 2-, 5-point fibers.
    for (const char* name : {"empty.tck", "multiline_header_field.tck", "simple.tck", "simple_big_endian.tck"}) {
        const std::string in = test::shared_data(std::string("conformance/") + name);
        const std::string out = dir.file(std::string(name) + ".fft");
        CommandResult r = run_cli("compress -q " + in + " -o " + out);
        ASSERT_EQ(r.status, 0) << name << "\n" << r.output;
        r = run_cli("stats " + out + " -r " + in + " --json");
        ASSERT_EQ(r.status, 0) << name << "\n" << r.output;
        const FftFile f(out);
        const Streamlines s = decode_fibers(f, 0, f.header().fibers);
        for (float v : s.xyz) ASSERT_TRUE(std::isfinite(v)) << name;
    }
}
