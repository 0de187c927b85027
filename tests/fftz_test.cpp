// The seekable zstd container (formats/fftz.md): the field transposition,
// random access to any block range against the plain .fft, the zstd
// seekable format (libzstd gives back the .fft), and damaged files.
#include <gtest/gtest.h>
#include <zstd.h>

#include <cmath>
#include <cstring>
#include <random>

#include "fiblet/block_index.hpp"
#include "fiblet/checksum.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/fftz_format.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

using namespace fiblet;

namespace {

void write_walks(const std::string& path, int count, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    TckWriter w(path, {{"step_size", "0.1"}}, true);
    for (int i = 0; i < count; ++i) {
        double p[3] = {10 * u(rng), 10 * u(rng), 10 * u(rng)}, d[3] = {1, 0, 0};
        std::vector<Vec3f> f;
        const int n = 1 + int(400 * std::fabs(u(rng)));
        for (int k = 0; k < n; ++k) {
            f.push_back({float(p[0]), float(p[1]), float(p[2])});
            for (double& c : d) c += 0.15 * u(rng);
            const double m = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (int a = 0; a < 3; ++a) d[a] /= m, p[a] += 0.1 * d[a];
        }
        w.write(f);
    }
    w.finish();
}

struct Files {
    test::TempDir dir;
    std::string plain, packed;
};

// The same tractogram as a plain .fft and as a .fftz (small groups, so
// that a range spans several frames); 16 bits: version 16 in both.
void make(Files& f, unsigned bits, bool transpose, std::uint32_t group = 7) {
    write_walks(f.dir.file("w.tck"), 60, 1);
    CompressOptions o;
    o.direction_bits = bits;
    o.fixed_blocks16 = true;
    o.search = search_for_effort(0);
    o.step_scale = 1.0;
    o.cap_ratio = 0.1;
    f.plain = f.dir.file("w.fft");
    compress_file(f.dir.file("w.tck"), f.plain, o);
    o.zstd = ZstdOptions{9, group, transpose};
    f.packed = f.dir.file("w.fftz");
    compress_file(f.dir.file("w.tck"), f.packed, o);
}

}  // namespace

TEST(FftzTranspose, IsInvertibleForBothBlockLayouts) {
    std::mt19937 rng(2);
    for (unsigned bits : {8u, 16u}) {
        const std::uint32_t bb = bits == 16 ? fft16_block_bytes(126) : fft_block_bytes(60);
        for (std::size_t n : {1u, 2u, 37u, 4096u}) {
            std::vector<std::uint8_t> blocks(n * bb);
            for (auto& b : blocks) b = std::uint8_t(rng());
            const auto t = transpose_block_group(blocks, bits, bb);
            ASSERT_EQ(t.size(), blocks.size());
            if (n > 1) {
                EXPECT_NE(t, blocks);
            }
            EXPECT_EQ(untranspose_block_group(t, bits, bb), blocks);
        }
    }
    EXPECT_THROW(transpose_block_group(std::vector<std::uint8_t>(75), 8, 76), Error);
}

TEST(FftzTranspose, StoresAnchorOneAsADifference) {
    // Two 8-bit blocks whose anchors 1 are anchor 0 + (1, 2, 3): the
    // difference planes hold 0, 0 (high bytes) and 1, 2, 3 (low bytes).
    std::vector<std::uint8_t> blocks(2 * 76, 0);
    for (int b = 0; b < 2; ++b) {
        std::uint8_t* p = &blocks[b * 76];
        const std::uint16_t q[6] = {1000, 2000, 3000, 1001, 2002, 3003};
        for (int k = 0; k < 3; ++k) {
            p[4 * k] = std::uint8_t(q[2 * k + 1] >> 8), p[4 * k + 1] = std::uint8_t(q[2 * k + 1]);
            p[4 * k + 2] = std::uint8_t(q[2 * k] >> 8), p[4 * k + 3] = std::uint8_t(q[2 * k]);
        }
    }
    const auto t = transpose_block_group(blocks, 8, 76);
    // Values x0 y0 z0 dx dy dz, two bytes each, two blocks per byte plane.
    for (int v = 3; v < 6; ++v) {
        EXPECT_EQ(t[(2 * v) * 2], 0) << v;
        EXPECT_EQ(t[(2 * v + 1) * 2], v - 2) << v;
    }
}

TEST(Fftz, ReadsEveryBlockRangeAsThePlainFile) {
    for (unsigned bits : {8u, 16u})
        for (bool transpose : {true, false}) {
            Files f;
            make(f, bits, transpose);
            const FftFile plain(f.plain), packed(f.packed);
            EXPECT_TRUE(packed.is_zstd_container());
            EXPECT_FALSE(plain.is_zstd_container());
            EXPECT_LT(packed.file_size(), plain.file_size());
            EXPECT_EQ(packed.logical_size(), plain.file_size());
            EXPECT_EQ(packed.header().blocks, plain.header().blocks);
            EXPECT_EQ(packed.header().max_error_mm, plain.header().max_error_mm);  // patched at the end
            EXPECT_EQ(packed.lut().size(), plain.lut().size());
            EXPECT_EQ(packed.properties(), plain.properties());
            const std::uint64_t nb = plain.header().blocks;
            std::mt19937 rng(bits + transpose);
            for (int i = 0; i < 60; ++i) {  // random ranges, in random order
                const std::uint64_t a = rng() % (nb + 1), b = rng() % (nb + 1);
                const std::uint64_t first = std::min(a, b), count = std::max(a, b) - first;
                EXPECT_EQ(packed.read_blocks(first, count), plain.read_blocks(first, count)) << first << "+" << count;
            }
            const Streamlines s1 = decode_fibers(plain, 0, plain.header().fibers),
                              s2 = decode_fibers(packed, 0, packed.header().fibers);
            EXPECT_EQ(s1.xyz, s2.xyz);
            EXPECT_EQ(s1.offsets, s2.offsets);
        }
}

TEST(Fftz, CarriesTheChecksumsAndIndexOfThePlainFileAndVerifies) {
    Files f;
    make(f, 8, true);
    const FftFile plain(f.plain), packed(f.packed);
    for (const auto tag : {kChecksumTag, kBlockIndexTag}) {
        ASSERT_NE(packed.find_chunk(tag), nullptr);
        EXPECT_EQ(packed.find_chunk(tag)->payload, plain.find_chunk(tag)->payload);
    }
    const VerifyReport r = verify_fft_file(f.packed);
    EXPECT_TRUE(r.has_checksum);
    EXPECT_EQ(r.blocks, plain.header().blocks);
    EXPECT_EQ(r.groups, verify_fft_file(f.plain).groups);
    EXPECT_EQ(r.points, plain.header().points);
    EXPECT_TRUE(r.index_checked);
    EXPECT_EQ(BlockIndex::load(packed).source(), BlockIndex::Source::chunk);
}

TEST(Fftz, IsAZstdStreamThatGivesBackThePlainFile) {
    Files f;
    make(f, 8, false);
    const std::string packed = test::read_file(f.packed), plain = test::read_file(f.plain);
    // libzstd decompresses the frames in order and skips the skippable ones.
    std::string out(plain.size() + 16, '\0');
    const std::size_t n = ZSTD_decompress(out.data(), out.size(), packed.data(), packed.size());
    ASSERT_FALSE(ZSTD_isError(n)) << ZSTD_getErrorName(n);
    out.resize(n);
    EXPECT_EQ(out, plain);
    // The seek table footer ends the file.
    std::uint32_t magic;
    std::memcpy(&magic, packed.data() + packed.size() - 4, 4);
    EXPECT_EQ(magic, kZstdSeekableFooterMagic);
}

TEST(Fftz, DamagedContainersAreRejected) {
    Files f;
    make(f, 8, true);
    const std::string packed = test::read_file(f.packed);
    auto opens_and_decodes = [&](const std::string& bytes) {
        test::write_file(f.dir.file("bad.fftz"), bytes);
        const FftFile file(f.dir.file("bad.fftz"));
        decode_fibers(file, 0, file.header().fibers);
    };
    EXPECT_THROW(opens_and_decodes(packed.substr(0, packed.size() - 1)), Error);    // seek table cut
    EXPECT_THROW(opens_and_decodes(packed.substr(0, packed.size() / 2)), Error);    // half the file
    std::string table = packed;
    table[table.size() - 9] ^= 1;  // frame count
    EXPECT_THROW(opens_and_decodes(table), Error);
    std::string body = packed;
    body[body.size() / 2] ^= 0x5a;  // inside a compressed group: its checksum fails
    EXPECT_THROW(opens_and_decodes(body), Error);
    std::string descriptor = packed;
    descriptor[12] = 9;  // container version
    EXPECT_THROW(opens_and_decodes(descriptor), Error);
}

TEST(Fftz, SeekTablesClaimingHugeFramesAreRejectedBeforeAllocating) {
    Files f;
    make(f, 8, true);
    std::string packed = test::read_file(f.packed);
    std::uint32_t frames;
    std::memcpy(&frames, packed.data() + packed.size() - 9, 4);
    // Entry of frame 2 (the LUT): decompressed size 4 GiB - 1.
    const std::size_t entry = packed.size() - 9 - 8 * frames + 8 * 2;
    const std::uint32_t huge = 0xffffffffu;
    std::memcpy(&packed[entry + 4], &huge, 4);
    test::write_file(f.dir.file("huge.fftz"), packed);
    EXPECT_THROW(FftFile{f.dir.file("huge.fftz")}, Error);
}

// A group frame followed by a stray byte that the seek table counts as its
// own: the reader refuses it as damage (exit 7's category), whole-frame
// decompression included.
TEST(Fftz, BytesAfterAGroupFrameAreDamage) {
    Files f;
    make(f, 8, true);
    const std::string packed = test::read_file(f.packed);
    std::uint32_t frames;
    std::memcpy(&frames, packed.data() + packed.size() - 9, 4);
    const std::size_t table = packed.size() - 9 - 8 * std::size_t(frames);
    // Frame 3: the first group of blocks (header, LUT and descriptor frames before it).
    std::size_t at = 0;
    for (std::uint32_t k = 0; k <= 3; ++k) {
        std::uint32_t stored;
        std::memcpy(&stored, &packed[table + 8 * k], 4);
        at += stored;
    }
    std::string damaged = packed;
    damaged.insert(at, 1, '\0');
    std::uint32_t stored;
    std::memcpy(&stored, &damaged[table + 1 + 8 * 3], 4);
    ++stored;
    std::memcpy(&damaged[table + 1 + 8 * 3], &stored, 4);
    test::write_file(f.dir.file("stray.fftz"), damaged);
    try {
        const FftFile file(f.dir.file("stray.fftz"));
        decode_fibers(file, 0, file.header().fibers);
        ADD_FAILURE() << "a stray byte after a frame was read";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), Errc::checksum) << e.what();
        EXPECT_NE(std::string(e.what()).find("after the end"), std::string::npos) << e.what();
    }
}
