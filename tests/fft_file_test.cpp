// FftFile validates everything before trusting a count: malformed files are
// rejected with Errc::fft_format, never read out of bounds.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

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
