// fiblet::read_track_scalars on files MRtrix3 wrote: tcksample's .tsf of a
// shared tractogram holds one value per point of each of its streamlines
// (counts read by fiblet's own .tck reader) and reads back as tcksample
// wrote them (values of a mask image: within [0, 1] up to rounding, interpolated).
#include <gtest/gtest.h>

#include "fiblet/tck.hpp"
#include "image_source.hpp"
#include "test_util.hpp"

namespace fiblet {
namespace {

TEST(TrackScalars, ReadsWhatTcksampleWrites) {
    if (!test::shared_data_available()) GTEST_SKIP() << "shared data not found";
    if (!test::have_mrtrix()) GTEST_SKIP() << "MRtrix3 not found";
    const test::TempDir dir;
    const std::string tck = dir.file("t.tck"), tsf = dir.file("t.tsf");
    const std::string mask = std::string(FIBLET_PHANTOM_FOD_DIR) + "/phantom-mask.nii";
    ASSERT_EQ(test::run_command("tckedit -quiet -number 40 " + test::shared_data("small-ifod1.tck") + " " + tck).status, 0);
    const auto sampled = test::run_command("tcksample -quiet " + tck + " " + mask + " " + tsf + " 2>&1");
    ASSERT_EQ(sampled.status, 0) << sampled.output;
    const std::vector<std::vector<float>> values = read_track_scalars(tsf);
    TckReader reader(tck);
    std::vector<Vec3f> fiber;
    std::size_t f = 0, inside = 0, between = 0;
    for (; reader.next(fiber); ++f) {
        ASSERT_LT(f, values.size());
        ASSERT_EQ(values[f].size(), fiber.size()) << "streamline " << f;
        for (const float v : values[f]) {
            EXPECT_TRUE(v >= -1e-6f && v <= 1 + 1e-6f) << v;  // trilinear weights round
            inside += v > 1 - 1e-6f, between += v > 1e-6f && v < 1 - 1e-6f;
        }
    }
    EXPECT_EQ(f, values.size());
    EXPECT_GT(inside, 0u);   // seeded in the mask: most points sample 1
    EXPECT_GT(between, 0u);  // trilinear at its edge
}

}  // namespace
}  // namespace fiblet
