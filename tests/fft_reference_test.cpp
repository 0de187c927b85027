// Compatibility with files written by another tool: the official Fiblets
// encoder's outputs in ../shared/data/reference decode to their input
// streamlines within the error their header records.
#include <gtest/gtest.h>

#include <cmath>

#include "fiblet/compare.hpp"
#include "fiblet/fft_file.hpp"
#include "test_util.hpp"

using namespace fiblet;

class OfficialEncoderFiles : public ::testing::TestWithParam<const char*> {};

TEST_P(OfficialEncoderFiles, DecodeToTheirInputWithinTheRecordedError) {
    const std::string name = GetParam();
    const std::string fft = test::shared_data("reference/" + name + ".fft");
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    const FftFile file(fft);
    EXPECT_EQ(file.header().points_per_block, 60u);
    EXPECT_EQ(file.header().block_bytes(), 76u);
    EXPECT_TRUE(file.trailer().empty());
    const Comparison c = compare_to_reference(file, test::shared_data(name + ".tck"));
    EXPECT_FALSE(c.resampled);
    EXPECT_EQ(c.error.count(), file.header().points);
    // Same fibers and points (compare_to_reference throws otherwise); the
    // error matches the header's up to float rounding order (0.2 %).
    EXPECT_NEAR(c.error.max_mm(), file.header().max_error_mm, 2e-3 * file.header().max_error_mm);
    EXPECT_NEAR(c.error.mean_mm(), file.header().mean_error_mm, 2e-3 * file.header().mean_error_mm);
}

INSTANTIATE_TEST_SUITE_P(Reference, OfficialEncoderFiles, ::testing::Values("small-ifod1", "small-sdstream"));
