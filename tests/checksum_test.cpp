// The CSUM chunk (formats/fft-checksum.md): what compress writes is checked
// against hashes recomputed here straight from the file's bytes, and every
// kind of silent corruption is reported as Errc::checksum where it is read.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "fiblet/checksum.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

using namespace fiblet;

namespace {

using test::at;

// A tractogram of `fibers` gently curving fibers of 40..159 points, with an
// empty fiber at index 1 (its LUT entry carries no block).
void write_tractogram(const std::string& path, int fibers) {
    TckWriter w(path, {{"step_size", "0.1"}}, true);
    std::vector<Vec3f> f;
    for (int i = 0; i < fibers; ++i) {
        f.clear();
        if (i != 1) {
            const int n = 40 + (i * 37) % 120;
            float x = float(i % 17), y = float(i % 11), z = 0, a = 0.01f * float(i);
            for (int k = 0; k < n; ++k) {
                f.push_back({x, y, z});
                a += 0.02f;
                x += 0.1f * std::cos(a), y += 0.1f * std::sin(a);
            }
        }
        w.write(f);
    }
    w.finish();
}

struct Fixture {
    test::TempDir dir;
    std::string fft = dir.file("a.fft");
    std::string bytes;
    FftHeader header;
    explicit Fixture(int fibers = 60) {
        write_tractogram(dir.file("a.tck"), fibers);
        // 60-point blocks (the default gives these smooth fibers 16 bits).
        CompressOptions o;
        o.direction_bits = 8;
        compress_file(dir.file("a.tck"), fft, o);
        bytes = test::read_file(fft);
        header = FftFile(fft).header();
    }
    std::string corrupt(std::size_t offset, std::uint8_t xor_mask = 0x01) const {
        std::string b = bytes;
        b[offset] = char(std::uint8_t(b[offset]) ^ xor_mask);
        const std::string path = dir.file("bad.fft");
        test::write_file(path, b);
        return path;
    }
};

// Opens and decodes everything; returns the error category, or nullopt.
std::optional<Errc> read_all(const std::string& path, FftOpenOptions o = {}) {
    return test::error_of([&] { decode_file(FftFile(path, o), [](std::uint64_t, const Streamlines&) {}); });
}

}  // namespace

TEST(Xxh64, PublishedValuesAndStreaming) {
    // Reference values of XXH64 with seed 0 (xxHash's documentation and xxhsum -H1).
    EXPECT_EQ(xxh64("", 0), 0xEF46DB3751D8E999ull);
    EXPECT_EQ(xxh64("abc", 3), 0x44BC2CF5AD770999ull);
    std::string data(100000, '\0');
    for (std::size_t i = 0; i < data.size(); ++i) data[i] = char(i * 2654435761u >> 13);
    Xxh64Stream s;
    for (std::size_t pos = 0, piece = 1; pos < data.size(); pos += piece, piece = piece * 3 % 997 + 1)
        s.update(data.data() + pos, std::min(piece, data.size() - pos));
    EXPECT_EQ(s.digest(), xxh64(data.data(), data.size()));
}

TEST(Checksum, CompressWritesHashesOfEveryPartAsLastChunk) {
    Fixture fx(600);  // > 1024 blocks: two groups, the last one partial
    const FftHeader& h = fx.header;
    ASSERT_GT(h.blocks, kDefaultChecksumGroupBlocks);
    ASSERT_NE(h.blocks % kDefaultChecksumGroupBlocks, 0u);
    const std::string& b = fx.bytes;
    // Walk the trailer from its footer, independently of FftFile.
    const std::uint64_t trailer = at<std::uint64_t>(b, b.size() - 16);
    ASSERT_EQ(trailer, h.file_bytes());
    std::uint64_t pos = trailer, csum = 0;
    std::string last_tag;
    while (pos < b.size() - 16) {
        last_tag = b.substr(pos, 4);
        if (last_tag == "CSUM") csum = pos;
        pos += 16 + at<std::uint64_t>(b, pos + 8);
    }
    ASSERT_EQ(last_tag, "CSUM");
    const std::size_t p = csum + 16;
    const std::uint64_t size = at<std::uint64_t>(b, csum + 8);
    const std::uint32_t g = at<std::uint32_t>(b, p + 4);
    EXPECT_EQ(at<std::uint32_t>(b, p), 1u);  // XXH64
    EXPECT_EQ(g, kDefaultChecksumGroupBlocks);
    const std::uint64_t groups = (h.blocks + g - 1) / g;
    ASSERT_EQ(size, 32 + 8 * groups);
    EXPECT_EQ(at<std::uint64_t>(b, p + 8), xxh64(b.data(), h.lut_offset()));
    EXPECT_EQ(at<std::uint64_t>(b, p + 16), xxh64(b.data() + h.lut_offset(), 8 * h.fibers));
    EXPECT_EQ(at<std::uint64_t>(b, p + 24), xxh64(b.data() + trailer, csum - trailer));
    for (std::uint64_t k = 0; k < groups; ++k) {
        const std::uint64_t b0 = k * g, b1 = std::min<std::uint64_t>(b0 + g, h.blocks);
        EXPECT_EQ(at<std::uint64_t>(b, p + 32 + 8 * k),
                  xxh64(b.data() + h.blocks_offset() + b0 * h.block_bytes(), (b1 - b0) * h.block_bytes()))
            << "group " << k;
    }
    const VerifyReport r = verify_fft_file(fx.fft);
    EXPECT_TRUE(r.has_checksum);
    EXPECT_EQ(r.groups, groups);
    EXPECT_EQ(r.blocks, h.blocks);
    EXPECT_EQ(r.points, h.points);
    EXPECT_EQ(r.ignored_trailing_bytes, 0u);
}

TEST(Checksum, BuilderIsIndependentOfHowBlocksAreSplit) {
    std::vector<std::uint8_t> blocks(76 * 2500);
    for (std::size_t i = 0; i < blocks.size(); ++i) blocks[i] = std::uint8_t(i * 131 >> 3);
    const std::vector<std::uint8_t> head(66, 7), lut(16, 9);
    FftChecksumBuilder whole(76, 1000), pieces(76, 1000);
    whole.add_lut(lut.data(), lut.size());
    whole.add_blocks(blocks.data(), blocks.size());
    pieces.add_lut(lut.data(), 5);
    pieces.add_lut(lut.data() + 5, lut.size() - 5);
    for (std::size_t pos = 0, piece = 1; pos < blocks.size(); pos += piece, piece = piece * 7 % 50021 + 1)
        pieces.add_blocks(blocks.data() + pos, std::min(piece, blocks.size() - pos));
    const TrailerChunk a = whole.finish(head, {}), c = pieces.finish(head, {});
    EXPECT_EQ(a.payload, c.payload);
    const FftChecksums s = FftChecksums::parse(a, 2500, "x");
    ASSERT_EQ(s.group_hashes.size(), 3u);
    EXPECT_EQ(s.group_hashes[2], xxh64(blocks.data() + 2000 * 76, 500 * 76));
}

TEST(Checksum, SilentCorruptionIsReportedWhereverItIs) {
    Fixture fx;
    const FftHeader& h = fx.header;
    ASSERT_EQ(read_all(fx.fft), std::nullopt);
    const std::uint64_t blocks = h.blocks_offset(), bb = h.block_bytes();
    struct Case {
        const char* what;
        std::size_t offset;
    };
    const Case cases[] = {
        {"header: mean error field", 53},
        {"LUT: block start of the empty fiber 1", std::size_t(h.lut_offset() + 8 + 4)},
        {"first block: anchor", std::size_t(blocks + 3)},
        {"block 5: a direction byte", std::size_t(blocks + 5 * bb + kBlockDirectionsOffset + 7)},
        {"last block: its last direction byte", std::size_t(blocks + h.blocks * bb - 1)},
        {"trailer: PROP payload", std::size_t(h.file_bytes() + 20)},
    };
    for (const Case& c : cases) {
        const std::string bad = fx.corrupt(c.offset);
        EXPECT_EQ(read_all(bad), Errc::checksum) << c.what;
        try {
            verify_fft_file(bad);
            ADD_FAILURE() << c.what << ": verify passed";
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), Errc::checksum) << c.what;
        }
        // Without verification the structure is still valid: it decodes.
        EXPECT_EQ(read_all(bad, {.verify_checksums = false}), std::nullopt) << c.what;
    }
}

TEST(Checksum, StructuralDamageIsAFormatErrorEvenWithAChecksum) {
    Fixture fx;
    const FftFile f(fx.fft);
    std::uint64_t fiber = 0;
    while (f.block_count(fiber) < 2) ++fiber;
    // Flags byte of the first block of a fiber of two or more blocks: "last" set.
    const std::uint64_t flags = fx.header.blocks_offset() + f.first_block(fiber) * fx.header.block_bytes() + kBlockFlagsOffset;
    EXPECT_EQ(read_all(fx.corrupt(flags, kFlagNotLast)), Errc::fft_format);
    EXPECT_EQ(read_all(fx.corrupt(0, 0x02)), Errc::fft_format);  // version 2 -> 0
}

TEST(Checksum, PartialDecodeVerifiesOnlyTheGroupsItReads) {
    Fixture fx(600);
    const FftFile good(fx.fft);
    const FftHeader& h = fx.header;
    // A direction byte in the last group; fibers wholly inside group 0 still decode.
    const std::uint64_t last_block = h.blocks - 1;
    const std::string bad = fx.corrupt(h.blocks_offset() + last_block * h.block_bytes() + kBlockDirectionsOffset);
    const FftFile f(bad);
    std::uint64_t end = 0;
    while (end < h.fibers && f.block_end(end + 1) <= kDefaultChecksumGroupBlocks / 2) ++end;
    ASSERT_GT(end, 2u);
    const Streamlines s = decode_fibers(f, 0, end), ref = decode_fibers(good, 0, end);
    EXPECT_EQ(s.xyz, ref.xyz);
    // A range ending inside the damaged group fails, even though the damaged
    // block itself is outside the range: the rest of the group is read to hash it.
    const std::uint64_t begin = h.fibers - 2;  // the last fiber holds the damaged block, this one does not
    ASSERT_LT(f.block_end(begin + 1), h.blocks);
    ASSERT_GE(f.first_block(begin), last_block / kDefaultChecksumGroupBlocks * kDefaultChecksumGroupBlocks);
    try {
        decode_fibers(f, begin, begin + 1);
        ADD_FAILURE() << "the damaged group was not verified";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), Errc::checksum);
    }
}

TEST(Checksum, FilesWithoutChecksumStillReadAndVerifySaysSo) {
    Fixture fx;
    // The same file cut after its blocks: what the official encoder writes.
    const std::string plain = fx.dir.file("plain.fft");
    test::write_file(plain, fx.bytes.substr(0, fx.header.file_bytes()));
    const FftFile f(plain);
    EXPECT_EQ(f.checksums(), nullptr);
    EXPECT_EQ(read_all(plain), std::nullopt);
    VerifyReport r = verify_fft_file(plain);
    EXPECT_FALSE(r.has_checksum);
    EXPECT_EQ(r.points, fx.header.points);
    EXPECT_EQ(r.ignored_trailing_bytes, 0u);
    if (test::shared_data_available()) {
        r = verify_fft_file(test::shared_data("reference/small-sdstream.fft"));
        EXPECT_FALSE(r.has_checksum);
        EXPECT_EQ(r.blocks, 14736u);
    }
}

TEST(Checksum, MalformedChunkOrUnknownAlgorithmIsAnIntegrityFailure) {
    TrailerChunk c{kChecksumTag, std::vector<std::uint8_t>(32 + 8 * 2, 0)};
    c.payload[0] = 1;
    c.payload[4] = 4;  // 4 blocks per group, 8 blocks: 2 groups
    EXPECT_NO_THROW(FftChecksums::parse(c, 8, "x"));
    auto code = [](const TrailerChunk& t, std::uint64_t blocks) {
        try {
            FftChecksums::parse(t, blocks, "x");
        } catch (const Error& e) {
            return e.code();
        }
        return Errc::interrupted;
    };
    // Without its CSUM chunk nothing in a fiblet-written file can be trusted.
    EXPECT_EQ(code(c, 9), Errc::checksum);  // 3 groups expected
    TrailerChunk zero = c;
    zero.payload[4] = 0;
    EXPECT_EQ(code(zero, 8), Errc::checksum);
    TrailerChunk other = c;
    other.payload[0] = 2;
    EXPECT_EQ(code(other, 8), Errc::checksum);
    TrailerChunk tiny{kChecksumTag, std::vector<std::uint8_t>(31, 0)};
    EXPECT_EQ(code(tiny, 0), Errc::checksum);
}

TEST(Checksum, AGroupFailsForEveryReaderUntilItVerifies) {
    Fixture fx(600);
    const FftHeader& h = fx.header;
    const std::string bad = fx.corrupt(h.blocks_offset() + 10 * h.block_bytes() + kBlockDirectionsOffset);
    const FftFile f(bad);
    std::vector<std::uint8_t> buf(100 * h.block_bytes());
    // Three readers of pieces of the damaged group: a failure is never remembered as a pass.
    for (std::uint64_t first : {0u, 200u, 500u}) {
        try {
            f.read_blocks(first, 100, buf.data());
            ADD_FAILURE() << "blocks " << first << "+100 read without error";
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), Errc::checksum);
        }
    }
    // Readers on four threads splitting the intact second group all succeed.
    const FftFile good(fx.fft);
    std::vector<std::thread> threads;
    std::atomic<int> failures{0};
    for (int t = 0; t < 4; ++t)
        threads.emplace_back([&, t] {
            std::vector<std::uint8_t> mine(40 * h.block_bytes());
            try {
                good.read_blocks(kDefaultChecksumGroupBlocks + 3 + 40 * std::uint64_t(t), 40, mine.data());
            } catch (const Error&) {
                ++failures;
            }
        });
    for (auto& t : threads) t.join();
    EXPECT_EQ(failures.load(), 0);
}

