// The 16-bit variant (formats/fft16.md) through the whole pipeline: its
// header and block layout, decoding with FftFile/decode_fibers, and the
// error the encoder records against an independent measurement.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "fiblet/compare.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

using namespace fiblet;

namespace {

// A small tractogram of helices at a 0.1 mm step, written as .tck.
void write_helices(const std::string& path, int count) {
    TckWriter w(path, {{"step_size", "0.1"}}, true);
    for (int i = 0; i < count; ++i) {
        std::vector<Vec3f> f;
        const double r = 5, pitch = 0.5 + 0.1 * i;  // one radius: every chord of 0.1 mm arc is as long
        const double dt = 0.1 / std::sqrt(r * r + pitch * pitch / (4 * M_PI * M_PI));
        for (int k = 0; k < 200 + 37 * i; ++k) {
            const double t = k * dt;
            f.push_back({float(i + r * std::cos(t)), float(r * std::sin(t)), float(pitch * t / (2 * M_PI))});
        }
        w.write(f);
    }
    w.finish();
}

}  // namespace

TEST(Fft16, CompressesToVersion16BlocksAndDecodesBelowAMicrometre) {
    test::TempDir dir;
    write_helices(dir.file("h.tck"), 12);
    CompressOptions o;
    o.direction_bits = 16;
    const CompressReport r = compress_tck(dir.file("h.tck"), dir.file("h.fft"), o);
    EXPECT_EQ(r.header.version, kFft16Version);
    EXPECT_EQ(r.header.points_per_block, kDefaultPointsPerBlock16);
    EXPECT_EQ(r.header.block_bytes(), 24u + 2 * (126 - 2));
    EXPECT_EQ(r.header.block_bytes() % 4, 0u);

    const FftFile file(dir.file("h.fft"));
    EXPECT_EQ(file.header().direction_bits(), 16u);
    EXPECT_EQ(file.header().blocks, r.header.blocks);
    // The first byte is the version: a version-2 reader stops there.
    EXPECT_EQ(test::read_file(dir.file("h.fft"))[0], char(16));

    const Comparison c = compare_to_reference(file, dir.file("h.tck"));
    EXPECT_EQ(c.points, r.header.points);
    EXPECT_NEAR(c.error.max_mm(), r.error.max_mm(), 1e-9);  // the encoder's closed loop is the decoder
    EXPECT_NEAR(c.error.mean_mm(), r.error.mean_mm(), 1e-9);
    EXPECT_LT(c.error.max_mm(), 1e-3);

    // Same data in 8 bits: 16-bit codes are far more precise.
    o.direction_bits = 8;
    const CompressReport r8 = compress_tck(dir.file("h.tck"), dir.file("h8.fft"), o);
    EXPECT_EQ(r8.header.version, kFftVersion);
    EXPECT_LT(10 * r.error.mean_mm(), r8.error.mean_mm());
}

TEST(Fft16, BlockFieldsHoldTheFiberLayout) {
    test::TempDir dir;
    write_helices(dir.file("h.tck"), 3);  // 200, 237, 274 points
    CompressOptions o;
    o.direction_bits = 16;
    o.points_per_block = 100;
    compress_tck(dir.file("h.tck"), dir.file("h.fft"), o);
    const FftFile file(dir.file("h.fft"));
    ASSERT_EQ(file.header().points_per_block, 100u);
    const std::uint32_t expected_counts[3][3] = {{100, 100, 0}, {100, 100, 37}, {100, 100, 74}};
    for (std::uint64_t f = 0; f < 3; ++f) {
        const auto blocks = file.read_blocks(file.first_block(f), file.block_count(f));
        for (std::uint32_t b = 0; b < file.block_count(f); ++b) {
            const BlockView16 v{&blocks[b * file.header().block_bytes()]};
            EXPECT_EQ(v.fiber_id(), f);
            EXPECT_EQ(v.point_count(), expected_counts[f][b]);
            EXPECT_EQ(v.is_first(), b == 0);
            EXPECT_EQ(v.is_last(), b + 1 == file.block_count(f));
        }
    }
    const Streamlines s = decode_fibers(file, 1, 3);
    EXPECT_EQ(s.size(), 2u);
    EXPECT_EQ(s.offsets[1], 237u);
    EXPECT_EQ(s.point_count(), 237u + 274u);
}

TEST(Fft16, RejectsBadCountsAndUnknownVersions) {
    test::TempDir dir;
    write_helices(dir.file("h.tck"), 2);
    CompressOptions o;
    o.direction_bits = 16;
    compress_tck(dir.file("h.tck"), dir.file("h.fft"), o);
    std::string bytes = test::read_file(dir.file("h.fft"));
    const FftFile good(dir.file("h.fft"));
    const std::size_t first_block = good.header().blocks_offset();

    std::string bad_version = bytes;
    bad_version[0] = 3;
    test::write_file(dir.file("v3.fft"), bad_version);
    EXPECT_THROW(FftFile{dir.file("v3.fft")}, Error);

    std::string bad_count = bytes;  // a block claiming more points than a block holds
    bad_count[first_block + kBlock16FlagsOffset] = char(0xff);
    bad_count[first_block + kBlock16FlagsOffset + 1] = char(0x3f);
    test::write_file(dir.file("count.fft"), bad_count);
    const FftFile f(dir.file("count.fft"));
    EXPECT_THROW(decode_fibers(f, 0, f.header().fibers), Error);

    std::string big_block = bytes;  // points per block above the 14-bit count
    const std::uint32_t too_many = kMaxPointsPerBlock16 + 1;
    std::memcpy(&big_block[21], &too_many, 4);
    test::write_file(dir.file("ppb.fft"), big_block);
    EXPECT_THROW(FftFile{dir.file("ppb.fft")}, Error);

    CompressOptions wrong;
    wrong.direction_bits = 12;
    EXPECT_THROW(compress_tck(dir.file("h.tck"), dir.file("x.fft"), wrong), Error);
}
