// `--max-error UM` on compress and stats: exit code 8 (cli_common.hpp
// kErrorBound) when a metric exceeds the bound, the report still printed and
// the output kept; 0 when all are within it; 2 for a bad value.
#include <gtest/gtest.h>

#include <filesystem>

#include "cli_runner.hpp"
#include "test_util.hpp"

namespace fiblet {
namespace {

constexpr int kErrorBound = 8;

TEST(MaxErrorCli, CompressAndStatsExitNonZeroAboveTheBound) {
    test::TempDir dir;
    const std::string tck = dir.file("three.tck"), fft = dir.file("three.fft");
    test::write_three_fiber_tck(tck);

    auto r = test::run_cli("compress " + tck + " -o " + fft + " --max-error 0.001");
    EXPECT_EQ(r.status, kErrorBound) << r.output;
    EXPECT_NE(r.output.find("above --max-error 0.001"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("Hausdorff"), std::string::npos) << r.output;  // the report was printed
    EXPECT_TRUE(std::filesystem::exists(fft));                            // and the output kept

    r = test::run_cli("compress " + tck + " -o " + fft + " --force --max-error 1000");
    EXPECT_EQ(r.status, 0) << r.output;

    r = test::run_cli("stats " + fft + " -r " + tck + " --max-error 0.001");
    EXPECT_EQ(r.status, kErrorBound) << r.output;
    r = test::run_cli("stats " + fft + " -r " + tck + " --json --max-error 0.001");
    EXPECT_EQ(r.status, kErrorBound) << r.output;
    EXPECT_NE(r.output.find("\"within_bound\": false"), std::string::npos) << r.output;
    r = test::run_cli("stats " + fft + " -r " + tck + " --json --max-error 1000");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("\"within_bound\": true"), std::string::npos) << r.output;

    r = test::run_cli("stats " + fft + " -r " + tck + " --max-error -3");
    EXPECT_EQ(r.status, 2) << r.output;
}

// A bound between the point error and the length change: the length change
// alone fails it (every metric counts, not just the point error).
TEST(MaxErrorCli, EveryMetricCounts) {
    test::TempDir dir;
    const std::string tck = dir.file("three.tck"), fft = dir.file("three.fft");
    test::write_three_fiber_tck(tck);
    ASSERT_EQ(test::run_cli("compress -q " + tck + " -o " + fft).status, 0);
    const auto json = test::run_cli("stats --json " + fft + " -r " + tck).output;
    auto number_after = [&](const std::string& key, std::size_t from = 0) {
        const std::size_t at = json.find("\"" + key + "\": ", from);
        EXPECT_NE(at, std::string::npos) << key;
        return std::stod(json.substr(at + key.size() + 4));
    };
    const double point = number_after("max_um");
    const double hausdorff = number_after("hausdorff_um");
    const double length = number_after("max_um", json.find("\"length_change\""));
    EXPECT_GE(hausdorff, 0.0);
    const double worst = std::max({point, hausdorff, length, number_after("max_um", json.find("\"endpoint\""))});
    EXPECT_EQ(test::run_cli("stats -q " + fft + " -r " + tck + " --max-error " + std::to_string(worst * 0.999)).status,
              kErrorBound);
    EXPECT_EQ(test::run_cli("stats -q " + fft + " -r " + tck + " --max-error " + std::to_string(worst * 1.001 + 1e-6)).status,
              0);
}

}  // namespace
}  // namespace fiblet
