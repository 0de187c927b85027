// Corrupt and truncated inputs, case by case: each bad file must stop with
// the exact error category (API) and exit code (CLI), and leave no output
// and no temporary file behind; the valid edge cases must round-trip.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "cli_runner.hpp"
#include "test_util.hpp"

using namespace fiblet;
namespace fs = std::filesystem;

namespace fiblet {
// Readable categories in assertion messages.
[[maybe_unused]] static void PrintTo(Errc c, std::ostream* os) { *os << errc_name(c); }
}  // namespace fiblet

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// The CLI's documented exit code for each category (docs/tour.md, "Exit codes, in detail").
int exit_code(Errc c) {
    switch (c) {
        case Errc::io: return 3;
        case Errc::tck_format:
        case Errc::trk_format:
        case Errc::trx_format:
        case Errc::fft_format:
        case Errc::invalid_input:
        case Errc::image_format: return 4;
        case Errc::invalid_argument: return 2;
        case Errc::exists: return 5;
        case Errc::unsupported: return 6;
        case Errc::checksum: return 7;
        case Errc::interrupted: return 130;
    }
    return 1;
}

int cli(const std::string& args, std::string* output = nullptr) {
    test::CommandResult r = test::run_cli(args);
    if (output) *output = std::move(r.output);
    return r.status;
}

std::vector<std::string> listing(const std::string& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

template <class T>
void append(std::string& s, T v) {
    s.append(reinterpret_cast<const char*>(&v), sizeof v);
}

std::string f32(std::initializer_list<float> values) {
    std::string s;
    for (float v : values) append(s, v);
    return s;
}

// A .tck file: "mrtrix tracks", `lines`, the file: entry (data right after END), data.
std::string tck(const std::string& data, const std::string& lines = "datatype: Float32LE\n") {
    const std::string head = "mrtrix tracks\n" + lines + "file: . ";
    const std::size_t fixed = head.size() + 5;  // + "\nEND\n"
    std::size_t offset = fixed + 1;
    while (std::to_string(offset).size() != offset - fixed) ++offset;
    return head + std::to_string(offset) + "\nEND\n" + data;
}

const std::string kSep = f32({kNaN, kNaN, kNaN});
const std::string kEnd = f32({kInf, kInf, kInf});
// Two fibers of 3 and 2 points at 0.5 mm spacing.
const std::string kTwoFibers = f32({0, 0, 0, 0.5f, 0, 0, 1, 0, 0}) + kSep + f32({0, 1, 0, 0, 1.5f, 0}) + kSep + kEnd;

using test::error_of;

// What `fiblet decompress` does, through the API.
void decompress(const std::string& in, const std::string& out) {
    const FftFile f(in);
    TckWriter w(out, f.properties(), false);
    decode_file(f, [&](std::uint64_t, const Streamlines& c) {
        for (std::size_t i = 0; i < c.size(); ++i) w.write(&c.xyz[3 * c.offsets[i]], c.offsets[i + 1] - c.offsets[i]);
    });
    w.finish();
}

struct TckCase {
    const char* what;
    std::string bytes;
    std::optional<Errc> error;  // nullopt: a valid edge case that must round-trip
    bool readable = false;      // the .tck reads; only compressing it fails
};

std::vector<TckCase> tck_cases() {
    const std::string good = tck(kTwoFibers);
    std::string oversized_header = "mrtrix tracks\n";
    while (oversized_header.size() <= (17u << 20)) oversized_header += "comment: " + std::string(100, 'x') + "\n";
    return {
        {"wrong magic", "mrtrix trackz\n" + good.substr(14), Errc::tck_format},
        {"binary garbage", std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16), Errc::tck_format},
        {"empty file", "", Errc::tck_format},
        {"missing END", "mrtrix tracks\ndatatype: Float32LE\nfile: . 60\ncount: 2\n", Errc::tck_format},
        {"header of 17 MiB without END", oversized_header, Errc::tck_format},
        {"missing file: entry", "mrtrix tracks\ndatatype: Float32LE\nEND\n" + kTwoFibers, Errc::tck_format},
        {"garbled file: offset", "mrtrix tracks\nfile: . 6x\nEND\n" + kTwoFibers, Errc::tck_format},
        {"file: in another file", "mrtrix tracks\nfile: data.bin 0\nEND\n", Errc::tck_format},
        {"offset past EOF", "mrtrix tracks\nfile: . 100000\nEND\n" + kTwoFibers, Errc::tck_format},
        {"offset inside the header", "mrtrix tracks\nfile: . 3\nEND\n" + kTwoFibers, Errc::tck_format},
        {"unknown datatype", tck(kTwoFibers, "datatype: Int16LE\n"), Errc::unsupported},
        {"truncated in the middle of a point", good.substr(0, good.size() - 12 - 12 - 5), Errc::tck_format},
        {"truncated after a separator (no end marker)", good.substr(0, good.size() - 12), Errc::tck_format},
        {"count: larger than the data", tck(kTwoFibers, "count: 3\n"), Errc::tck_format},
        {"count: smaller than the data", tck(kTwoFibers, "count: 1\n"), Errc::tck_format},
        {"NaN in one coordinate", tck(f32({0, 0, 0, 1, kNaN, 0}) + kSep + kEnd), Errc::tck_format},
        {"Inf in one coordinate", tck(f32({0, 0, 0, 1, 0, -kInf}) + kSep + kEnd), Errc::tck_format},
        {"float64 beyond the float32 range",
         tck(
             [] {
                 std::string d;
                 for (double v : {0.0, 0.0, 0.0, 1e300, 0.0, 0.0}) append(d, v);
                 const double nan = std::nan(""), inf = HUGE_VAL;
                 for (double v : {nan, nan, nan, inf, inf, inf}) append(d, v);
                 return d;
             }(),
             "datatype: Float64LE\n"),
         Errc::invalid_input},
        {"coordinates spanning more than the float range", tck(f32({-3e38f, 0, 0, 3e38f, 0, 0}) + kSep + kEnd),
         Errc::invalid_input, true},
        {"a step so near the float range that decoded points overflow (found by compress_fuzz)",
         tck(f32({1, 2, 3}) + kSep + f32({4, 7.3982334e31f, 0, -2.4570463f, 0, 0, 1.17e-32f, 2.8175146e20f, 3.1964534e38f, 1, 2, 3}) + kSep + kEnd),
         Errc::invalid_input, true},
        {"a step lost against the extent (1e25 mm apart, 0.1 mm steps)",
         tck(f32({0, 0, 0, 0.1f, 0, 0, 0.2f, 0, 0}) + kSep + f32({1e25f, 0, 0, 1e25f, 0.1f, 0}) + kSep + kEnd),
         Errc::invalid_input, true},
        {"resampling would need more than 65535 blocks",
         tck(
             [] {
                 // 40 steps of 1 um (the median), then a fiber running 5 times across
                 // 0.9 m: 4.5 m of 1 um steps, in a box the float step still resolves
                 std::string d;
                 for (int i = 0; i <= 40; ++i) d += f32({1e-3f * float(i), 0, 0});
                 return d + kSep + f32({0, 1, 0, 900, 1, 0, 0, 1, 0, 900, 1, 0, 0, 1, 0, 900, 1, 0}) + kSep + kEnd;
             }()),
         Errc::unsupported, true},
        // Valid edge cases.
        {"a diagonal step longer than the bounding box's sides", tck(f32({0, 0, 0, 1, 1, 1}) + kSep + kEnd),
         std::nullopt},
        {"zero-length fibers", tck(kSep + f32({0, 0, 0, 0.5f, 0, 0}) + kSep + kSep + kEnd, "count: 3\n"), std::nullopt},
        {"single-point fibers", tck(f32({1, 2, 3}) + kSep + f32({4, 5, 6}) + kSep + kEnd), std::nullopt},
        {"zero fibers (end marker only)", tck(kEnd, "count: 0\n"), std::nullopt},
        {"zero fibers (empty data section)", tck(""), std::nullopt},
    };
}

struct FftCase {
    const char* what;
    std::function<void(std::string&)> corrupt;
    Errc error;
};

template <class T>
void poke(std::string& b, std::size_t off, T v) {
    std::memcpy(b.data() + off, &v, sizeof v);
}

// A valid .fft with checksums: 3 fibers of 70, 10 and 1 points (blocks 2 + 1 + 1).
std::string valid_fft(const test::TempDir& dir) {
    test::write_three_fiber_tck(dir.file("src.tck"));
    compress_file(dir.file("src.tck"), dir.file("valid.fft"), {});
    std::string b = test::read_file(dir.file("valid.fft"));
    fs::remove(dir.file("src.tck"));
    fs::remove(dir.file("valid.fft"));
    return b;
}

std::vector<FftCase> fft_cases() {
    const std::size_t lut = kFftFixedHeaderBytes + 8, blocks = lut + 3 * 8, bb = 76;
    return {
        {"empty file", [](std::string& b) { b.clear(); }, Errc::fft_format},
        // Recognised and named (tractogram_format.hpp), not parsed as a .fft.
        {"a .tck file", [](std::string& b) { b = tck(kTwoFibers); }, Errc::unsupported},
        {"wrong version", [](std::string& b) { b[0] = 1; }, Errc::fft_format},
        {"truncated header", [](std::string& b) { b.resize(40); }, Errc::fft_format},
        {"truncated buffer table", [](std::string& b) { b.resize(kFftFixedHeaderBytes + 4); }, Errc::fft_format},
        {"truncated LUT", [&](std::string& b) { b.resize(lut + 12); }, Errc::fft_format},
        {"truncated block", [&](std::string& b) { b.resize(blocks + 3 * bb + 30); }, Errc::fft_format},
        {"fiber LUT pointing past the end", [&](std::string& b) { poke<std::uint32_t>(b, lut + 8 + 4, 70000u); },
         Errc::fft_format},
        {"fiber LUT with more blocks than the file", [&](std::string& b) { poke<std::uint32_t>(b, lut, 40000u); },
         Errc::fft_format},
        {"huge fiber count", [](std::string& b) { poke<std::uint64_t>(b, 1, ~std::uint64_t{0} / 4); },
         Errc::fft_format},
        {"block count x size overflowing the file", [](std::string& b) { poke<std::uint32_t>(b, 17, 0xffffffffu); },
         Errc::fft_format},
        {"huge buffer end", [](std::string& b) { poke<std::uint64_t>(b, kFftFixedHeaderBytes, ~std::uint64_t{0}); },
         Errc::fft_format},
        {"block with 0 points", [&](std::string& b) { b[blocks + kBlockFlagsOffset] = char(kFlagNotLast | 0); },
         Errc::fft_format},
        {"block with 61 points (60 per block)",
         [&](std::string& b) { b[blocks + kBlockFlagsOffset] = char(kFlagNotLast | 61); }, Errc::fft_format},
        {"block with 63 points (60 per block)",
         [&](std::string& b) { b[blocks + 2 * bb + kBlockFlagsOffset] = char(63); }, Errc::fft_format},
        {"first block of a fiber flagged 'not first'",
         [&](std::string& b) { b[blocks + 2 * bb + kBlockFlagsOffset] |= char(kFlagNotFirst); }, Errc::fft_format},
        {"middle of a fiber flagged 'last'",
         [&](std::string& b) { b[blocks + kBlockFlagsOffset] &= char(~kFlagNotLast); }, Errc::fft_format},
        {"NaN scaling", [](std::string& b) { poke<float>(b, 25, std::nanf("")); }, Errc::fft_format},
        {"zero scaling", [](std::string& b) { poke<float>(b, 25, 0.0f); }, Errc::fft_format},
        {"NaN ratio", [](std::string& b) { poke<float>(b, 41, std::nanf("")); }, Errc::fft_format},
        {"ratio above 2", [](std::string& b) { poke<float>(b, 41, 2.5f); }, Errc::fft_format},
        {"infinite offset", [](std::string& b) { poke<float>(b, 33, -kInf); }, Errc::fft_format},
        {"NaN step", [](std::string& b) { poke<float>(b, 45, std::nanf("")); }, Errc::fft_format},
        {"points per block 0", [](std::string& b) { poke<std::uint32_t>(b, 21, 0u); }, Errc::fft_format},
        {"points per block 64", [](std::string& b) { poke<std::uint32_t>(b, 21, 64u); }, Errc::fft_format},
        {"more points than the blocks hold", [](std::string& b) { poke<std::uint64_t>(b, 9, 1u << 20); },
         Errc::fft_format},
        // A fiblet trailer that does not parse is damage, never "no checksum".
        {"trailer footer pointing elsewhere", [](std::string& b) { poke<std::uint64_t>(b, b.size() - 16, 12u); },
         Errc::checksum},
        {"trailer chunk running past the footer",
         [&](std::string& b) { poke<std::uint64_t>(b, blocks + 4 * bb + 8, std::uint64_t{1} << 40); },
         Errc::checksum},
        {"flipped bit in a direction byte", [&](std::string& b) { b[blocks + kBlockDirectionsOffset + 20] ^= 4; },
         Errc::checksum},
        {"flipped bit in an anchor", [&](std::string& b) { b[blocks + bb + 1] ^= 1; }, Errc::checksum},
        {"flipped bit in the recorded error", [](std::string& b) { b[50] ^= 1; }, Errc::checksum},
    };
}

}  // namespace

TEST(CorruptTck, EachCaseFailsWithItsCategoryAndLeavesNoOutput) {
    test::TempDir dir;
    for (const TckCase& c : tck_cases()) {
        SCOPED_TRACE(c.what);
        const std::string in = dir.file("in.tck"), out = dir.file("out.fft");
        test::write_file(in, c.bytes);
        // API: reading, then the whole compression.
        EXPECT_EQ(error_of([&] { test::read_tck_fibers(in); }), c.readable ? std::nullopt : c.error);
        EXPECT_EQ(error_of([&] { compress_file(in, out, {}); }), c.error);
        if (c.error) {
            EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"in.tck"});
        } else {
            // A valid edge case: the fibers come back with their point counts.
            const auto original = test::read_tck_fibers(in);
            EXPECT_EQ(error_of([&] { decompress(out, dir.file("back.tck")); }), std::nullopt);
            const auto back = test::read_tck_fibers(dir.file("back.tck"));
            ASSERT_EQ(back.size(), original.size());
            for (std::size_t i = 0; i < back.size(); ++i) {
                ASSERT_EQ(back[i].size(), original[i].size()) << "fiber " << i;
                for (std::size_t k = 0; k < back[i].size(); ++k) {
                    EXPECT_NEAR(back[i][k].x, original[i][k].x, 1e-3) << "fiber " << i;
                    EXPECT_NEAR(back[i][k].y, original[i][k].y, 1e-3) << "fiber " << i;
                    EXPECT_NEAR(back[i][k].z, original[i][k].z, 1e-3) << "fiber " << i;
                }
            }
            fs::remove(out);
            fs::remove(dir.file("back.tck"));
        }
        // CLI.
        std::string msg;
        EXPECT_EQ(cli("compress -q " + in + " -o " + out, &msg), c.error ? exit_code(*c.error) : 0) << msg;
        if (c.error) {
            EXPECT_NE(msg.find("error"), std::string::npos) << msg;
            EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"in.tck"});
        }
        fs::remove(out);
    }
}

TEST(CorruptTck, MissingOrUnreadableInputIsAnIoError) {
    test::TempDir dir;
    EXPECT_EQ(error_of([&] { compress_file(dir.file("nope.tck"), dir.file("o.fft"), {}); }), Errc::io);
    EXPECT_EQ(error_of([&] { compress_file(dir.path(), dir.file("o.fft"), {}); }), Errc::io);
    // The output directory does not exist.
    test::write_file(dir.file("in.tck"), tck(kTwoFibers));
    EXPECT_EQ(error_of([&] { compress_file(dir.file("in.tck"), dir.file("no/such/dir/o.fft"), {}); }), Errc::io);
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"in.tck"});
}

TEST(CorruptFft, EachCaseFailsWithItsCategoryAndLeavesNoOutput) {
    test::TempDir dir;
    const std::string good = valid_fft(dir);
    ASSERT_EQ(good.substr(good.size() - 8), "FIBLETX1");
    for (const FftCase& c : fft_cases()) {
        SCOPED_TRACE(c.what);
        std::string bytes = good;
        c.corrupt(bytes);
        ASSERT_NE(bytes, good);
        const std::string in = dir.file("in.fft"), out = dir.file("out.tck");
        test::write_file(in, bytes);
        // API: opening and decoding everything, and a decompression.
        EXPECT_EQ(error_of([&] {
                      const FftFile f(in);
                      decode_file(f, [](std::uint64_t, const Streamlines&) {});
                  }),
                  c.error);
        EXPECT_EQ(error_of([&] { decompress(in, out); }), c.error);
        EXPECT_EQ(error_of([&] { verify_fft_file(in); }), c.error);
        EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"in.fft"});
        // CLI.
        std::string msg;
        EXPECT_EQ(cli("decompress -q " + in + " -o " + out, &msg), exit_code(c.error)) << msg;
        EXPECT_NE(msg.find("error"), std::string::npos) << msg;
        EXPECT_EQ(cli("verify -q " + in, &msg), exit_code(c.error)) << msg;
        EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"in.fft"});
    }
    // The unmodified file passes everything.
    test::write_file(dir.file("in.fft"), good);
    EXPECT_EQ(error_of([&] { decompress(dir.file("in.fft"), dir.file("out.tck")); }), std::nullopt);
    EXPECT_EQ(cli("verify " + dir.file("in.fft")), 0);
}

TEST(CorruptTck, AStreamlineLongerThanAFiberCanHoldIsRefusedBeforeItFillsMemory) {
    test::TempDir dir;
    // 2 points per block: at most 65535 * 2 points per fiber.
    std::string data;
    for (int i = 0; i < 65535 * 2 + 1; ++i) data += f32({0.1f * float(i % 1000), 0.0f, 0.1f * float(i / 1000)});
    test::write_file(dir.file("in.tck"), tck(data + kSep + kEnd));
    CompressOptions o;
    o.points_per_block = 2;
    EXPECT_EQ(error_of([&] { compress_file(dir.file("in.tck"), dir.file("out.fft"), o); }), Errc::unsupported);
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"in.tck"});
    // The reader's own limit.
    EXPECT_EQ(error_of([&] {
                  TckReader r(dir.file("in.tck"), {.chunk_bytes = 1 << 10, .max_points = 1000});
                  std::vector<Vec3f> f;
                  r.next(f);
              }),
              Errc::unsupported);
}
