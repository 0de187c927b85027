// Golden bytes: a tiny hand-built tractogram whose .fft bytes are checked
// field by field, so the layout cannot drift.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "fiblet/compress.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

using namespace fiblet;

namespace {
using test::at;
std::uint8_t byte(const std::string& b, std::size_t off) { return static_cast<std::uint8_t>(b[off]); }
}  // namespace

TEST(FftGolden, TinyTractogramLayout) {
    test::TempDir dir;
    // Fiber 0: 3 points along +x at 1 mm spacing in a box [0,4]x[0,2]x[0,1];
    // fiber 1: 62 points (two blocks: 60 + 2); fiber 2: a single point.
    std::vector<std::vector<Vec3f>> fibers;
    fibers.push_back({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}});
    std::vector<Vec3f> f1;
    for (int i = 0; i < 62; ++i) f1.push_back({4.0f - float(i) / 61.0f * 4.0f, 2.0f, 1.0f});
    fibers.push_back(f1);
    fibers.push_back({{4, 2, 1}});
    {
        TckWriter w(dir.file("in.tck"), {{"step_size", "1"}}, false);
        for (const auto& f : fibers) w.write(f);
        w.finish();
    }
    CompressOptions o;
    o.step_mm = 1.0;
    o.step_tolerance = 100;  // never resample (fiber 1's spacing is 4/61): this test is about layout
    o.direction_bits = 8;    // version 2's layout (the default gives straight fibers 16 bits)
    compress_file(dir.file("in.tck"), dir.file("out.fft"), o);
    const std::string b = test::read_file(dir.file("out.fft"));

    // Header.
    EXPECT_EQ(byte(b, 0), 2);                          // version
    EXPECT_EQ(at<std::uint64_t>(b, 1), 3u);            // fibers
    EXPECT_EQ(at<std::uint64_t>(b, 9), 66u);           // points
    EXPECT_EQ(at<std::uint32_t>(b, 17), 4u);           // blocks: 1 + 2 + 1
    EXPECT_EQ(at<std::uint32_t>(b, 21), 60u);          // points per block
    const float scaling = at<float>(b, 25);
    EXPECT_NEAR(scaling, 4.0f, 1e-4f);                 // largest extent (x)
    EXPECT_FLOAT_EQ(at<float>(b, 29), -2.0f);          // offset = -(min+max)/2
    EXPECT_FLOAT_EQ(at<float>(b, 33), -1.0f);
    EXPECT_FLOAT_EQ(at<float>(b, 37), -0.5f);
    EXPECT_NEAR(at<float>(b, 45) * scaling, 1.0f, 1e-6f);  // step, normalized
    EXPECT_EQ(byte(b, 57), 1);                         // one GPU buffer
    EXPECT_EQ(at<std::uint64_t>(b, 58), 4u);           // ... ending at block 4
    // Fiber LUT at 66: (buffer << 16 | blocks, first block in buffer).
    EXPECT_EQ(at<std::uint32_t>(b, 66), 1u);
    EXPECT_EQ(at<std::uint32_t>(b, 70), 0u);
    EXPECT_EQ(at<std::uint32_t>(b, 74), 2u);
    EXPECT_EQ(at<std::uint32_t>(b, 78), 1u);
    EXPECT_EQ(at<std::uint32_t>(b, 82), 1u);
    EXPECT_EQ(at<std::uint32_t>(b, 86), 3u);
    const std::size_t blocks = 90;

    // Block 0: anchors (0,0,0) and (1,0,0), normalized as (p + offset) / scaling + 0.5.
    auto unorm = [&](float world, int axis) {
        const float offs[3] = {-2.0f, -1.0f, -0.5f};
        return std::uint16_t(std::lround(std::clamp((world + offs[axis]) / scaling + 0.5f, 0.0f, 1.0f) * 65535.0f));
    };
    auto word = [&](std::size_t off) {  // most-significant byte first
        return std::uint32_t(byte(b, off)) << 24 | std::uint32_t(byte(b, off + 1)) << 16 |
               std::uint32_t(byte(b, off + 2)) << 8 | byte(b, off + 3);
    };
    EXPECT_EQ(word(blocks + 0), std::uint32_t(unorm(0, 0)) | std::uint32_t(unorm(0, 1)) << 16);  // x0 | y0
    EXPECT_EQ(word(blocks + 4), std::uint32_t(unorm(0, 2)) | std::uint32_t(unorm(1, 0)) << 16);  // z0 | x1
    EXPECT_EQ(word(blocks + 8), std::uint32_t(unorm(0, 1)) | std::uint32_t(unorm(0, 2)) << 16);  // y1 | z1
    // The same, as literal bytes: x0 = 0, y0 = 0.25 -> 0x4000, z0 = 0.375 -> 0x6000,
    // x1 = 0.25, y1 = 0.25, z1 = 0.375.
    EXPECT_EQ(b.substr(blocks, 12), std::string("\x40\x00\x00\x00\x40\x00\x60\x00\x60\x00\x40\x00", 12));
    EXPECT_EQ(std::string(b.data() + blocks + 12, 4), std::string("\0\0\0\0", 4));  // fiber 0, big-endian
    EXPECT_EQ(byte(b, blocks + 16), 3);               // first and last block, 3 points
    EXPECT_EQ(byte(b, blocks + 17), 0);               // block index in fiber

    // Fiber 1: block 1 (first, not last, 60 points), block 2 (not first, last, 2 points).
    EXPECT_EQ(std::string(b.data() + blocks + 76 + 12, 4), std::string("\0\0\0\x01", 4));
    EXPECT_EQ(byte(b, blocks + 76 + 16), 0x40 | 60);
    EXPECT_EQ(byte(b, blocks + 2 * 76 + 16), 0x80 | 2);
    EXPECT_EQ(byte(b, blocks + 2 * 76 + 17), 1);
    // Fiber 2: one point; ID 2 big-endian.
    EXPECT_EQ(std::string(b.data() + blocks + 3 * 76 + 12, 4), std::string("\0\0\0\x02", 4));
    EXPECT_EQ(byte(b, blocks + 3 * 76 + 16), 1);
    // Then the fiblet trailer, ending with the footer magic.
    EXPECT_EQ(b.substr(b.size() - 8), "FIBLETX1");
    EXPECT_EQ(at<std::uint64_t>(b, b.size() - 16), blocks + 4 * 76u);
}
