// The 16-bit variants (formats/fft16.md) through the whole pipeline: their
// header and block layouts (packed version 17 in a .fft, version 16 in a
// .fftz), decoding with FftFile/decode_fibers and with the float64
// reference decoder, the error the encoder records against an independent
// measurement, and the reader's strictness on malformed packed files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "fiblet/checksum.hpp"
#include "fiblet/compare.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "cli_runner.hpp"
#include "container/packed_blocks16.hpp"
#include "exact_error.hpp"
#include "scoped_simd_loops.hpp"
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

// Bytes of a packed block of n points (formats/fft16.md), from the spec.
std::uint64_t packed_bytes(std::uint64_t n) { return 18 + (n > 2 ? (15 * (n - 2) + 7) / 8 : 0); }

TEST(Fft16, CompressesToPackedVersion17AndDecodesBelowAMicrometre) {
    test::TempDir dir;
    write_helices(dir.file("h.tck"), 12);
    CompressOptions o;
    o.direction_bits = 16;
    const CompressReport r = compress_file(dir.file("h.tck"), dir.file("h.fft"), o);
    EXPECT_EQ(r.header.version, kFft16PackedVersion);
    EXPECT_EQ(r.header.points_per_block, 254u);
    EXPECT_EQ(r.header.code_levels(), 181u);

    const FftFile file(dir.file("h.fft"));
    EXPECT_EQ(file.header().direction_bits(), 16u);
    EXPECT_EQ(file.header().blocks, r.header.blocks);
    // The first byte is the version: a version-2 reader stops there.
    EXPECT_EQ(test::read_file(dir.file("h.fft"))[0], char(17));
    // No padding: every fiber's blocks hold 254 points but its last, packed back to back.
    std::uint64_t blocks_bytes = 0;
    for (int i = 0; i < 12; ++i) {
        std::uint64_t n = 200 + 37 * i;
        for (; n > 254; n -= 254) blocks_bytes += packed_bytes(254);
        blocks_bytes += packed_bytes(n);
    }
    EXPECT_EQ(file.header().file_bytes(), file.header().blocks_offset() + blocks_bytes);

    const Comparison c = compare_to_reference(file, dir.file("h.tck"));
    EXPECT_EQ(c.points, r.header.points);
    EXPECT_LT(c.error.max_mm(), 1e-3);

    // The float64 reference decoder, written from the spec, agrees.
    const test::ExactMeasurement m = test::measure_exact(dir.file("h.fft"), dir.file("h.tck"));
    EXPECT_EQ(m.exact.points, r.header.points);
    EXPECT_TRUE(std::isfinite(m.exact.mean_mm()));  // every point decodes (the straight-ahead code too)
    EXPECT_LT(m.exact.max_mm, 1e-3);
    // The recorded max error is the worse of the two decoders' (the encoder
    // walks both), up to the encoder's float world coordinates (0.48 nm
    // measured; the two decoders differ by 2.9 nm here).
    EXPECT_NEAR(r.error.max_mm(), std::max(c.error.max_mm(), m.exact.max_mm), 1e-6);
    EXPECT_LE(c.error.mean_mm(), r.error.mean_mm() + 1e-9);

    // Same data in 8 bits: the 181-level codes are 12 times finer per axis
    // (9.3 times smaller a mean error measured on these helices).
    o.direction_bits = 8;
    const CompressReport r8 = compress_file(dir.file("h.tck"), dir.file("h8.fft"), o);
    EXPECT_EQ(r8.header.version, kFftVersion);
    EXPECT_LT(6 * r.error.mean_mm(), r8.error.mean_mm());
}

TEST(Fft16, ZstdContainersHoldVersion16) {
    test::TempDir dir;
    write_helices(dir.file("h.tck"), 4);
    CompressOptions o;
    o.direction_bits = 16;
    o.zstd = ZstdOptions{};
    const CompressReport r = compress_file(dir.file("h.tck"), dir.file("h.fftz"), o);
    EXPECT_EQ(r.header.version, kFft16Version);
    EXPECT_EQ(r.header.points_per_block, kDefaultPointsPerBlock16);
    EXPECT_EQ(r.header.block_bytes(), 24u + 2 * (126 - 2));
    const FftFile file(dir.file("h.fftz"));
    EXPECT_EQ(file.header().code_levels(), 256u);
    const Comparison c = compare_to_reference(file, dir.file("h.tck"));
    // Recorded: the worse of the float decoder and an exact one, which
    // differ by the float walk's rounding (nanometres here).
    EXPECT_LE(c.error.max_mm(), r.error.max_mm() + 1e-9);
    EXPECT_NEAR(c.error.max_mm(), r.error.max_mm(), 1e-5);
    EXPECT_LT(c.error.max_mm(), 1e-3);
}

TEST(Fft16, BlockFieldsHoldTheFiberLayout) {
    test::TempDir dir;
    write_helices(dir.file("h.tck"), 3);  // 200, 237, 274 points
    CompressOptions o;
    o.direction_bits = 16;
    o.points_per_block = 100;
    compress_file(dir.file("h.tck"), dir.file("h.fft"), o);
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

TEST(Fft16, RejectsMalformedPackedFiles) {
    test::TempDir dir;
    write_helices(dir.file("h.tck"), 2);  // 200 and 237 points: one block each
    CompressOptions o;
    o.direction_bits = 16;
    compress_file(dir.file("h.tck"), dir.file("h.fft"), o);
    const std::string bytes = test::read_file(dir.file("h.fft"));
    const FftFile good(dir.file("h.fft"));
    const std::size_t first_block = good.header().blocks_offset(), lut = good.header().lut_offset();
    auto variant = [&](const std::string& name, auto change) {
        std::string b = bytes;
        change(b);
        test::write_file(dir.file(name), b);
        return dir.file(name);
    };
    auto errc_of = [](auto&& action) {  // the error's code, -1 for none
        try {
            action();
        } catch (const Error& e) {
            return int(e.code());
        }
        return -1;
    };
    const int fft_format = int(Errc::fft_format), checksum = int(Errc::checksum);

    std::string bad_version = bytes;
    bad_version[0] = 3;
    test::write_file(dir.file("v3.fft"), bad_version);
    EXPECT_THROW(FftFile{dir.file("v3.fft")}, Error);

    // A code past the 181 x 181 levels (0x7fff): the block is malformed,
    // with or without checksums (structure is checked first).
    const std::string code = variant("code.fft", [&](std::string& b) {
        b[first_block + 18] = char(0xff), b[first_block + 19] = char(b[first_block + 19] | 0x7f);
    });
    for (const bool verify : {false, true}) {
        const FftFile f(code, {.verify_checksums = verify});
        EXPECT_EQ(errc_of([&] { decode_fibers(f, 0, f.header().fibers); }), fft_format);
    }
    // The CLI says so and exits with 4.
    const test::CommandResult cli = test::run_cli("decompress -q -f " + code + " -o " + dir.file("code.tck"));
    EXPECT_EQ(cli.status, 4) << cli.output;
    EXPECT_NE(cli.output.find("past the 181 x 181 levels"), std::string::npos) << cli.output;
    // A well-formed change (an anchor byte) is caught by the checksums of the blocks' content.
    const std::string anchor = variant("anchor.fft", [&](std::string& b) { b[first_block + 4] ^= 1; });
    const FftFile checked(anchor);
    EXPECT_EQ(errc_of([&] { decode_fibers(checked, 0, checked.header().fibers); }), checksum);

    // Non-zero bits after the last code: 198 codes fill 2970 bits, the
    // block's last byte (371 after the anchors) has 6 unused bits.
    const std::string pad = variant("pad.fft", [&](std::string& b) {
        b[first_block + 18 + 371] = char(b[first_block + 18 + 371] | 0x80);
    });
    const FftFile p(pad, {.verify_checksums = false});
    EXPECT_EQ(errc_of([&] { decode_fibers(p, 0, 1); }), fft_format);

    // The LUT's point count must fit the fiber's block count, and sum to the header's.
    const auto set_points = [&](std::uint32_t points) {
        return [&, points](std::string& b) { std::memcpy(&b[lut + 4], &points, 4); };
    };
    EXPECT_EQ(errc_of([&] { FftFile{variant("blocks.fft", set_points(300)), {.verify_checksums = false}}; }),
              fft_format);
    EXPECT_EQ(errc_of([&] { FftFile{variant("sum.fft", set_points(201)), {.verify_checksums = false}}; }),
              fft_format);
    // Blocks cut short: the packed size exceeds the file.
    EXPECT_EQ(errc_of([&] {
                  FftFile{variant("short.fft", [&](std::string& b) { b.resize(first_block + 100); }),
                          {.verify_checksums = false, .ignore_trailer = true}};
              }),
              fft_format);

    std::string big_block = bytes;  // points per block above the 14-bit count
    const std::uint32_t too_many = kMaxPointsPerBlock16 + 1;
    std::memcpy(&big_block[21], &too_many, 4);
    test::write_file(dir.file("ppb.fft"), big_block);
    EXPECT_THROW(FftFile{dir.file("ppb.fft")}, Error);

    CompressOptions wrong;
    wrong.direction_bits = 12;
    EXPECT_THROW(compress_file(dir.file("h.tck"), dir.file("x.fft"), wrong), Error);
}

// Version 17's checksum groups hash the blocks as stored, packed
// (formats/fft-checksum.md), so a reader verifies what it reads without
// expanding a group's other blocks; every flipped byte of the blocks is
// still caught, as a checksum or a format error.
TEST(Fft16, ChecksumGroupsHashThePackedBytes) {
    test::TempDir dir;
    write_helices(dir.file("h.tck"), 3);  // 200, 237, 274 points: 4 blocks
    CompressOptions o;
    o.direction_bits = 16;
    compress_file(dir.file("h.tck"), dir.file("h.fft"), o);
    const std::string bytes = test::read_file(dir.file("h.fft"));
    const FftFile good(dir.file("h.fft"));
    const std::size_t first_block = good.header().blocks_offset(), end = good.header().file_bytes();
    // From the spec: the CSUM payload's first group hash (offset 32) is of
    // bytes [blocksOffset, end of the blocks) when there is one group.
    const std::string csum = test::exact::trailer_chunk(bytes, "CSUM");
    ASSERT_EQ(csum.size(), 40u);
    std::uint64_t group0 = 0;
    std::memcpy(&group0, csum.data() + 32, 8);
    EXPECT_EQ(group0, xxh64(bytes.data() + first_block, end - first_block));

    // Every fifth byte, and the last (anchors, codes, the padding bits).
    for (std::size_t at = first_block; at < end; at = at + 5 < end || at + 1 == end ? at + 5 : end - 1) {
        std::string b = bytes;
        b[at] = char(b[at] ^ 0x10);
        test::write_file(dir.file("flip.fft"), b);
        int code = -1;
        try {
            const FftFile f(dir.file("flip.fft"));
            decode_fibers(f, 0, f.header().fibers);
        } catch (const Error& e) {
            code = int(e.code());
        }
        EXPECT_TRUE(code == int(Errc::checksum) || code == int(Errc::fft_format)) << "byte " << at << ": " << code;
        if (at == first_block + 100) {  // a code byte: verify says so, with the checksum exit status
            const test::CommandResult r = test::run_cli("verify " + dir.file("flip.fft"));
            EXPECT_EQ(r.status, 7) << r.output;
        }
    }
}

// Packing then expanding a block gives its codes back at every point count
// (each tail of the sixteen- and eight-codes-at-a-time readers), and a code
// past the levels is found wherever it sits; with the AVX2 loop and without.
TEST(Fft16, PackedCodesRoundTripAndBadCodesAreFoundAnywhere) {
    for (const bool avx2 : {true, false}) {
        SCOPED_TRACE(avx2 ? "AVX2 loop" : "scalar loops");
        const test::ScopedSimdLoops loops(avx2);
        FftHeader h;
        h.version = kFft16PackedVersion;
        h.points_per_block = 254;
        std::mt19937 rng(5);
        std::uniform_int_distribution<int> code(0, 181 * 181 - 1);
        for (std::uint32_t n = 1; n <= 254; ++n) {
            SCOPED_TRACE(n);
            std::vector<std::uint8_t> block(h.block_bytes(), 0);
            const std::uint16_t flags = std::uint16_t(n);  // first and last of its fiber
            std::memcpy(&block[kBlock16FlagsOffset], &flags, 2);
            for (std::size_t b = 0; b < kBlock16FiberIdOffset; ++b) block[b] = std::uint8_t(rng());
            const std::uint32_t m = n > 2 ? n - 2 : 0;
            for (std::uint32_t k = 0; k < m; ++k) {
                const auto c = std::uint16_t(code(rng));
                std::memcpy(&block[kBlock16DirectionsOffset + 2 * k], &c, 2);
            }
            std::vector<std::uint8_t> packed;
            detail::pack_blocks16(h, block, packed);
            const detail::PackedBlockPlace place{n, 0, true, true};
            std::vector<std::uint8_t> out(h.block_bytes(), 0xee);
            ASSERT_EQ(detail::expand_block16(h, packed.data(), place, out.data()), "");
            EXPECT_TRUE(std::equal(block.begin() + kBlock16DirectionsOffset, block.end(), out.begin() + kBlock16DirectionsOffset));
            EXPECT_TRUE(std::equal(block.begin(), block.begin() + kBlock16FiberIdOffset, out.begin()));
            for (std::uint32_t k = 0; k < m; k += 1 + k / 16) {  // a code past the levels at k
                std::vector<std::uint8_t> bad = block;
                const std::uint16_t past = std::uint16_t(181 * 181 + k % 7);
                std::memcpy(&bad[kBlock16DirectionsOffset + 2 * k], &past, 2);
                std::vector<std::uint8_t> bad_packed;
                detail::pack_blocks16(h, bad, bad_packed);
                EXPECT_NE(detail::expand_block16(h, bad_packed.data(), place, out.data()), "") << "code " << k;
            }
        }
    }
}
