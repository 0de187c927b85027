// FftFile validates everything before trusting a count: malformed files are
// rejected with Errc::fft_format, never read out of bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

using namespace fiblet;

namespace {

// A small valid .fft (3 fibers, 4 blocks) as bytes.
std::string make_valid(const test::TempDir& dir) {
    test::write_three_fiber_tck(dir.file("in.tck"));
    compress_file(dir.file("in.tck"), dir.file("ok.fft"), {.overwrite = true});
    return test::read_file(dir.file("ok.fft"));
}

template <class T>
void poke(std::string& b, std::size_t off, T v) {
    std::memcpy(b.data() + off, &v, sizeof v);
}

Errc open_error(const test::TempDir& dir, const std::string& bytes) {
    test::write_file(dir.file("bad.fft"), bytes);
    try {
        FftFile f(dir.file("bad.fft"));
        // Opened: decoding must then fail cleanly or succeed.
        const Streamlines s = decode_fibers(f, 0, f.header().fibers);
        (void)s;
    } catch (const Error& e) {
        return e.code();
    }
    return Errc::interrupted;  // "no error" marker for the assertions below
}

}  // namespace

TEST(FftFile, ReadsItsOwnOutput) {
    test::TempDir dir;
    test::write_file(dir.file("x.fft"), make_valid(dir));
    const FftFile f(dir.file("x.fft"));
    EXPECT_EQ(f.header().fibers, 3u);
    EXPECT_EQ(f.header().points, 81u);
    EXPECT_EQ(f.header().blocks, 4u);
    EXPECT_EQ(f.block_count(0), 2u);
    EXPECT_EQ(f.first_block(2), 3u);
    EXPECT_NE(f.find_chunk(kPropertiesTag), nullptr);
}

TEST(FftFile, RejectsMalformedFiles) {
    test::TempDir dir;
    const std::string good = make_valid(dir);
    const std::size_t lut = kFftFixedHeaderBytes + 8;  // one buffer
    struct Case {
        const char* what;
        std::function<void(std::string&)> corrupt;
    };
    const std::vector<Case> cases = {
        {"empty file", [](std::string& b) { b.clear(); }},
        {"wrong version", [](std::string& b) { b[0] = 3; }},
        {"truncated header", [](std::string& b) { b.resize(30); }},
        {"truncated buffer table", [](std::string& b) { b.resize(kFftFixedHeaderBytes + 3); }},
        {"truncated LUT", [&](std::string& b) { b.resize(lut + 10); }},
        {"truncated block", [&](std::string& b) { b.resize(lut + 24 + 3 * 76 + 40); }},
        {"huge fiber count", [](std::string& b) { poke<std::uint64_t>(b, 1, std::uint64_t(1) << 60); }},
        {"huge block count", [](std::string& b) { poke<std::uint32_t>(b, 17, 0xffffffffu); }},
        {"points per block 0", [](std::string& b) { poke<std::uint32_t>(b, 21, 0u); }},
        {"points per block 64", [](std::string& b) { poke<std::uint32_t>(b, 21, 64u); }},
        {"NaN scaling", [](std::string& b) { poke<float>(b, 25, std::nanf("")); }},
        {"negative scaling", [](std::string& b) { poke<float>(b, 25, -1.0f); }},
        {"NaN ratio", [](std::string& b) { poke<float>(b, 41, std::nanf("")); }},
        {"infinite offset", [](std::string& b) { poke<float>(b, 29, std::numeric_limits<float>::infinity()); }},
        {"buffer table not ending at block count", [](std::string& b) { poke<std::uint64_t>(b, kFftFixedHeaderBytes, 3u); }},
        {"LUT pointing past the end", [&](std::string& b) { poke<std::uint32_t>(b, lut + 4, 1000u); }},
        {"LUT block count too large", [&](std::string& b) { poke<std::uint32_t>(b, lut, 9u); }},
        {"LUT buffer index past the table", [&](std::string& b) { poke<std::uint32_t>(b, lut, (5u << 16) | 2u); }},
        {"block with 0 points", [&](std::string& b) { b[lut + 24 + 16] = char(0x40); }},
        {"block with 61 points", [&](std::string& b) { b[lut + 24 + 16] = char(0x40 | 61); }},
        {"more points than the blocks hold", [](std::string& b) { poke<std::uint64_t>(b, 9, 1000u); }},
    };
    for (const Case& c : cases) {
        std::string b = good;
        c.corrupt(b);
        EXPECT_EQ(open_error(dir, b), Errc::fft_format) << c.what;
    }
    EXPECT_EQ(open_error(dir, good), Errc::interrupted) << "the unmodified file must decode";
}

TEST(FftFile, MissingFileIsAnIoError) {
    try {
        FftFile f("/nonexistent/x.fft");
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), Errc::io);
    }
}

namespace {

// 400 helices of 600 points: 4,000 blocks over four checksum groups.
std::string compress_curves(const test::TempDir& dir, const CompressOptions& o = {}) {
    test::write_helix_tck(dir.file("curves.tck"), 400, 600);
    const std::string out = dir.file(o.zstd ? "curves.fftz" : "curves.fft");
    compress_file(dir.file("curves.tck"), out, o);
    return out;
}

}  // namespace

// Scattered spans copied out of the mapping are the blocks read_blocks
// reads, one span after the other, in a fresh FftFile each time (so every
// checksum group is verified through the mapping itself).
TEST(FftFile, ReadBlocksMappedEqualsReadBlocks) {
    test::TempDir dir;
    const std::string path = compress_curves(dir);
    const std::uint64_t blocks = FftFile(path).header().blocks;
    ASSERT_GT(blocks, 3000u);
    std::mt19937 rng(7);
    for (int trial = 0; trial < 20; ++trial) {
        const FftFile mapped(path), read(path);
        std::vector<FftFile::BlockSpan> spans;
        std::vector<std::uint8_t> expected;
        for (std::uint64_t b = rng() % 40; b < blocks; b += 1 + rng() % 200) {
            const std::uint64_t count = std::min<std::uint64_t>(1 + rng() % 5, blocks - b);
            spans.push_back({b, count});
            const auto r = read.read_blocks(b, count);
            expected.insert(expected.end(), r.begin(), r.end());
            b += count;
        }
        std::vector<std::uint8_t> got(expected.size());
        ASSERT_TRUE(mapped.read_blocks_mapped(spans, got.data()));
        EXPECT_EQ(got, expected) << "trial " << trial;
    }
}

TEST(FftFile, ReadBlocksMappedChecksWhatItCopies) {
    test::TempDir dir;
    const std::string path = compress_curves(dir);
    const FftHeader h = FftFile(path).header();
    std::vector<std::uint8_t> out(8 * h.block_bytes());
    {  // out of range, or not ascending
        const FftFile f(path);
        const FftFile::BlockSpan past{h.blocks - 1, 2}, back[2] = {{10, 2}, {11, 1}};
        EXPECT_EQ(test::error_of([&] { f.read_blocks_mapped({&past, 1}, out.data()); }), Errc::invalid_argument);
        EXPECT_EQ(test::error_of([&] { f.read_blocks_mapped(back, out.data()); }), Errc::invalid_argument);
    }
    // A direction byte of block 2500 flipped: its group's checksum fails.
    ASSERT_GT(h.blocks, 3000u);
    std::string bytes = test::read_file(path);
    bytes[h.blocks_offset() + 2500 * h.block_bytes() + h.block_bytes() - 1] ^= 0x10;
    test::write_file(dir.file("flipped.fft"), bytes);
    const FftFile flipped(dir.file("flipped.fft"));
    const FftFile::BlockSpan around{2498, 4};
    EXPECT_EQ(test::error_of([&] { flipped.read_blocks_mapped({&around, 1}, out.data()); }), Errc::checksum);
    // A container has no blocks to map: nothing read, read_blocks then.
    CompressOptions z;
    z.zstd = ZstdOptions{};
    const FftFile fftz(compress_curves(dir, z));
    const FftFile::BlockSpan first{0, 2};
    EXPECT_FALSE(fftz.read_blocks_mapped({&first, 1}, out.data()));
}
