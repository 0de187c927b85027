// Integrity that damage cannot switch off (issue classes 1-3 and 5): a
// damaged trailer is an integrity failure, trailer values are validated,
// verify cross-checks what readers rely on, claimed sizes are not trusted
// before they are real, and a sweep of every single-bit flip of a small
// file finds none that verify passes while the decoded file changes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fiblet/block_index.hpp"
#include "fiblet/checksum.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/tck.hpp"
#include "cli_runner.hpp"
#include "test_util.hpp"

using namespace fiblet;

namespace {

using test::kSanitized;

// Smooth curves at a fixed 0.1 mm step: `fibers` of 50..349 points.
void write_tractogram(const std::string& path, int fibers) {
    TckWriter w(path, {{"comment", "trailer test"}}, true);
    std::vector<Vec3f> f;
    for (int i = 0; i < fibers; ++i) {
        f.clear();
        float x = float(i % 7), y = float(i % 5), z = float(i % 3), a = 0.1f * float(i);
        for (int k = 0; k < 50 + (i * 37) % 300; ++k) {
            f.push_back({x, y, z});
            a += 0.03f;
            x += 0.1f * std::cos(a), y += 0.1f * std::sin(a) * 0.8f, z += 0.06f;
        }
        w.write(f);
    }
    w.finish();
}

// The trailer chunks of a fiblet file, walked independently of FftFile.
struct Chunk {
    std::string tag;
    std::size_t at, size;  // of the whole chunk (16-byte head + payload)
};
std::vector<Chunk> walk_trailer(const std::string& b, std::uint64_t end) {
    std::vector<Chunk> out;
    for (std::size_t pos = end; pos < b.size() - 16;) {
        const auto size = std::size_t(16 + test::at<std::uint64_t>(b, pos + 8));
        out.push_back({b.substr(pos, 4), pos, size});
        pos += size;
    }
    return out;
}

struct Fixture {
    test::TempDir dir;
    std::string tck = dir.file("a.tck"), fft = dir.file("a.fft");
    std::string bytes;
    FftHeader header;
    explicit Fixture(int fibers = 40, CompressOptions o = {}) {
        write_tractogram(tck, fibers);
        compress_file(tck, fft, o);
        bytes = test::read_file(fft);
        header = FftFile(fft).header();
    }
    std::string write(const std::string& name, const std::string& b) const {
        const std::string path = dir.file(name);
        test::write_file(path, b);
        return path;
    }
    // A copy with the header, LUT and blocks edited by `edit_body` and the
    // trailer's chunks replaced by `edit_chunks`, and a CSUM chunk that
    // matches it all: what a faulty writer (not damage) would make.
    std::string rewritten(const std::string& name, const std::function<void(std::string&)>& edit_body,
                          const std::function<void(std::vector<TrailerChunk>&)>& edit_chunks = {}) const {
        std::string body = bytes.substr(0, header.file_bytes());
        if (edit_body) edit_body(body);
        std::vector<TrailerChunk> chunks;
        const FftFile source(fft);
        for (const TrailerChunk& c : source.trailer())
            if (c.tag != kChecksumTag) chunks.push_back(c);
        if (edit_chunks) edit_chunks(chunks);
        return write(name, test::with_checksummed_trailer(body, header, chunks));
    }
};

std::optional<Errc> open_error(const std::string& path, FftOpenOptions o = {}) {
    return test::error_of([&] { decode_file(FftFile(path, o), [](std::uint64_t, const Streamlines&) {}); });
}

std::optional<Errc> verify_error(const std::string& path) {
    return test::error_of([&] { verify_fft_file(path); });
}

// Everything a reader gets from a file: every point, every offset, the
// source properties (nullopt when the file does not open or decode).
struct Decoded {
    Streamlines s;
    std::vector<std::pair<std::string, std::string>> properties;
    bool operator==(const Decoded& o) const {
        return s.offsets == o.s.offsets && s.xyz == o.s.xyz && properties == o.properties;
    }
};
std::optional<Decoded> decoded(const std::string& path, FftOpenOptions o = {}) {
    try {
        const FftFile f(path, o);
        return Decoded{decode_fibers(f, 0, f.header().fibers), f.properties()};
    } catch (const Error&) {
        return std::nullopt;
    }
}

void put_u64(std::string& b, std::size_t at, std::uint64_t v) { std::memcpy(&b[at], &v, 8); }

}  // namespace

// Class 1: once anything follows the blocks, the trailer must be complete.
TEST(TrailerIntegrity, DamagedTrailerIsAnIntegrityFailureNeverNoChecksum) {
    Fixture fx;
    const std::uint64_t end = fx.header.file_bytes();
    const auto chunks = walk_trailer(fx.bytes, end);
    ASSERT_GE(chunks.size(), 2u);
    ASSERT_EQ(chunks.back().tag, "CSUM");
    struct Case {
        const char* what;
        std::string bytes;
    };
    std::vector<Case> cases;
    auto flipped = [&](std::size_t at, std::uint8_t mask) {
        std::string b = fx.bytes;
        b[at] = char(std::uint8_t(b[at]) ^ mask);
        return b;
    };
    cases.push_back({"CSUM tag turned into another tag", flipped(chunks.back().at + 1, 0x04)});
    cases.push_back({"one bit in the first chunk's size", flipped(chunks.front().at + 8, 0x01)});
    cases.push_back({"one bit in the first chunk's size, high", flipped(chunks.front().at + 13, 0x10)});
    cases.push_back({"damaged footer magic", flipped(fx.bytes.size() - 3, 0x20)});
    cases.push_back({"footer offset", flipped(fx.bytes.size() - 16, 0x08)});
    cases.push_back({"truncated by one byte", fx.bytes.substr(0, fx.bytes.size() - 1)});
    cases.push_back({"truncated inside the trailer", fx.bytes.substr(0, end + 20)});
    cases.push_back({"4 KiB of zeros appended", fx.bytes + std::string(4096, '\0')});
    cases.push_back({"a second footer appended", fx.bytes + fx.bytes.substr(fx.bytes.size() - 16)});
    const Decoded original = *decoded(fx.fft);
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        const std::string path = fx.write("bad.fft", c.bytes);
        EXPECT_EQ(open_error(path), Errc::checksum);
        EXPECT_EQ(open_error(path, {.verify_checksums = false}), Errc::checksum);  // not a checksum to skip
        EXPECT_EQ(verify_error(path), Errc::checksum);
        const auto v = test::run_cli("verify " + path);
        EXPECT_EQ(v.status, 7) << v.output;
        EXPECT_NE(v.output.find("damaged trailer"), std::string::npos) << v.output;
        const std::string out = fx.dir.file("out.tck");
        EXPECT_EQ(test::run_cli("decompress -q " + path + " -o " + out).status, 7);
        EXPECT_FALSE(std::filesystem::exists(out));
        // The explicit escape salvages the blocks, and says what it gave up.
        const auto salvaged = test::run_cli("decompress -q --ignore-trailer " + path + " -o " + out);
        EXPECT_EQ(salvaged.status, 0) << salvaged.output;
        EXPECT_NE(salvaged.output.find("--ignore-trailer"), std::string::npos) << salvaged.output;
        const auto blocks = decoded(path, {.ignore_trailer = true});
        ASSERT_TRUE(blocks);
        ASSERT_EQ(blocks->s.offsets, original.s.offsets);
        EXPECT_TRUE(blocks->properties.empty());
        // The same points, but each fiber's last, whose kept end (the ENDS
        // chunk) is lost with the trailer: it lies at most one step further.
        for (std::size_t f = 0; f + 1 < original.s.offsets.size(); ++f)
            for (std::uint64_t i = original.s.offsets[f]; i < original.s.offsets[f + 1]; ++i)
                for (int a = 0; a < 3; ++a) {
                    const float got = blocks->s.xyz[3 * i + a], want = original.s.xyz[3 * i + a];
                    if (i + 1 < original.s.offsets[f + 1]) {
                        ASSERT_EQ(got, want) << "fiber " << f << " point " << i;
                    } else {
                        ASSERT_NEAR(got, want, 1.01 * fx.header.step * fx.header.scaling) << "fiber " << f;
                    }
                }
        std::filesystem::remove(out);
    }
    // Official-encoder files end with their last block and keep working.
    const std::string plain = fx.write("plain.fft", fx.bytes.substr(0, end));
    EXPECT_EQ(open_error(plain), std::nullopt);
    EXPECT_EQ(test::run_cli("verify " + plain).status, 0);
    EXPECT_EQ(test::run_cli("verify --require-checksum " + plain).status, 7);
}

// Class 2: values the checksum covers can still be wrong (a faulty writer).
TEST(TrailerIntegrity, TrailerValuesAreValidatedForEveryReader) {
    CompressOptions o;
    o.step_tolerance = 0;  // any spacing variation resamples: the file gets an RSMP chunk
    Fixture fx(40, o);
    ASSERT_TRUE(FftFile(fx.fft).resampled_step_mm());
    auto with_rsmp = [&](double step, const std::string& name) {
        return fx.rewritten(name, {}, [&](std::vector<TrailerChunk>& chunks) {
            for (TrailerChunk& c : chunks)
                if (c.tag == kResampledTag) std::memcpy(c.payload.data(), &step, 8);
        });
    };
    const double step_mm = double(fx.header.step) * fx.header.scaling;
    for (const double step : {0.0, std::nan(""), -0.1, std::numeric_limits<double>::infinity(), 100 * step_mm}) {
        SCOPED_TRACE(step);
        const std::string path = with_rsmp(step, "rsmp.fft");
        EXPECT_EQ(open_error(path), Errc::fft_format);
        EXPECT_EQ(verify_error(path), Errc::fft_format);
        // Before the fix, stats resampled the reference with this step forever.
        const auto stats = test::run_command("timeout 20 " + std::string(FIBLET_CLI) + " stats " + path +
                                             " --reference " + fx.tck + " 2>&1");
        EXPECT_EQ(stats.status, 4) << stats.output;
        EXPECT_NE(stats.output.find("RSMP"), std::string::npos) << stats.output;
        EXPECT_EQ(test::run_cli("extract " + path + " --fibers 0-3 -o " + fx.dir.file("x.fft")).status, 4);
        EXPECT_FALSE(std::filesystem::exists(fx.dir.file("x.fft")));
    }
    EXPECT_EQ(open_error(with_rsmp(step_mm, "ok.fft")), std::nullopt);
    // The curve field: 0 (polyline) to 3 (rounded corners), then a zero
    // word; other sizes are not RSMP chunks.
    auto with_curve = [&](std::vector<std::uint32_t> words, const std::string& name) {
        return fx.rewritten(name, {}, [&](std::vector<TrailerChunk>& chunks) {
            for (TrailerChunk& c : chunks)
                if (c.tag == kResampledTag) {
                    c.payload.resize(8 + 4 * words.size());
                    std::memcpy(c.payload.data() + 8, words.data(), 4 * words.size());
                }
        });
    };
    EXPECT_EQ(FftFile(fx.fft).resampling()->curve, ResampleCurve::rounded_keeping_length);
    EXPECT_EQ(FftFile(with_curve({2, 0}, "tension.fft")).resampling()->curve, ResampleCurve::cubic_keeping_length);
    EXPECT_EQ(FftFile(with_curve({1, 0}, "cubic.fft")).resampling()->curve, ResampleCurve::cubic);
    EXPECT_EQ(FftFile(with_curve({0, 0}, "polyline.fft")).resampling()->curve, ResampleCurve::polyline);
    for (const auto& words : std::vector<std::vector<std::uint32_t>>{{4, 0}, {1, 1}, {1}, {1, 0, 0}}) {
        SCOPED_TRACE(words.size());
        EXPECT_EQ(open_error(with_curve(words, "curve.fft")), Errc::fft_format);
    }
    // A chunk twice, a PROP string running past its chunk, a key no .tck can hold.
    const std::string twice = fx.rewritten("twice.fft", {}, [](std::vector<TrailerChunk>& c) { c.push_back(c[0]); });
    EXPECT_EQ(open_error(twice), Errc::fft_format);
    const std::string long_string = fx.rewritten("prop.fft", {}, [](std::vector<TrailerChunk>& chunks) {
        chunks[0].payload[0] = 0xff;
    });
    EXPECT_EQ(open_error(long_string), Errc::fft_format);
    const std::string colon = fx.rewritten("colon.fft", {}, [](std::vector<TrailerChunk>& chunks) {
        chunks[0] = make_properties_chunk({{"a:b", "c"}});
    });
    EXPECT_EQ(open_error(colon), Errc::fft_format);
}

// Class 3: verify fails on anything a reader would decode differently from
// what the writer meant, with or without checksums.
TEST(TrailerIntegrity, VerifyCrossChecksWhatReadersRelyOn) {
    Fixture fx(40);
    const FftFile good(fx.fft);
    const FftHeader& h = fx.header;
    const std::uint64_t bb = h.block_bytes();
    std::uint64_t middle = 0;
    while (middle < h.fibers && good.block_count(middle) < 4) ++middle;
    ASSERT_LT(middle, h.fibers) << "the fixture needs a fiber of 4+ blocks";
    const std::uint64_t m1 = h.blocks_offset() + (good.first_block(middle) + 1) * bb, m2 = m1 + bb;

    // Header point count off by one (the blocks hold one more).
    const std::string points = fx.rewritten("points.fft", [&](std::string& b) { put_u64(b, 9, h.points - 1); },
                                            [](std::vector<TrailerChunk>& c) {
                                                std::erase_if(c, [](const TrailerChunk& k) { return k.tag == kBlockIndexTag; });
                                            });
    EXPECT_EQ(verify_error(points), Errc::fft_format);
    EXPECT_NE(test::run_cli("verify " + points).output.find("points"), std::string::npos);
    // decompress would report one count and write another: it fails, and writes nothing.
    const std::string out = fx.dir.file("points.tck");
    EXPECT_EQ(test::run_cli("decompress " + points + " -o " + out).status, 4);
    EXPECT_FALSE(std::filesystem::exists(out));
    // Two middle blocks of a fiber swapped (same flags and counts): the block
    // index bytes give it away, with or without a checksum.
    const std::string swapped = fx.rewritten("swapped.fft", [&](std::string& b) {
        const std::string first = b.substr(m1, bb);
        b.replace(m1, bb, b.substr(m2, bb));
        b.replace(m2, bb, first);
    });
    EXPECT_EQ(verify_error(swapped), Errc::fft_format);
    EXPECT_EQ(open_error(swapped), Errc::fft_format);
    const std::string swapped_plain = fx.write("swapped-plain.fft", test::read_file(swapped).substr(0, h.file_bytes()));
    EXPECT_EQ(verify_error(swapped_plain), Errc::fft_format);
    // A block carrying another fiber's ID.
    const std::string moved = fx.rewritten("moved.fft", [&](std::string& b) { b[m1 + kBlockFiberIdOffset + 3] ^= 1; });
    EXPECT_EQ(verify_error(moved), Errc::fft_format);
    // Every BIDX box shrunk to the grid's first cell: a selection would
    // silently lose the fibers; verify decodes the blocks and sees it.
    const std::string shrunk = fx.rewritten("shrunk.fft", {}, [&](std::vector<TrailerChunk>& chunks) {
        for (TrailerChunk& c : chunks)
            if (c.tag == kBlockIndexTag) {
                const std::size_t codes = 72 + h.fibers;  // one byte of last-block points per fiber
                for (std::size_t i = codes; i < c.payload.size(); ++i) c.payload[i] = 0;
            }
    });
    EXPECT_EQ(open_error(shrunk), std::nullopt);  // well-formed: only the blocks can tell
    EXPECT_EQ(verify_error(shrunk), Errc::fft_format);
    const auto v = test::run_cli("verify " + shrunk);
    EXPECT_EQ(v.status, 4);
    EXPECT_NE(v.output.find("BIDX"), std::string::npos) << v.output;
    EXPECT_EQ(verify_error(fx.fft), std::nullopt);
}

// Class 5: a .fftz whose seek table and header claim a 1 GiB LUT that its
// frame does not hold fails without allocating the claim.
TEST(TrailerIntegrity, ClaimedSizesAreNotAllocatedBeforeTheyAreReal) {
    CompressOptions o;
    o.zstd = ZstdOptions{};
    Fixture fx(3, o);
    std::string b = fx.bytes;
    // Seek table: entries of 8 bytes (compressed, decompressed size) before a 9-byte footer.
    const std::uint32_t frames = test::at<std::uint32_t>(b, b.size() - 9);
    const std::size_t entries = b.size() - 9 - 8 * std::size_t(frames);
    const std::uint64_t claimed_fibers = std::uint64_t{1} << 27;
    std::uint32_t lut_bytes = std::uint32_t(8 * claimed_fibers);
    std::memcpy(&b[entries + 8 * 2 + 4], &lut_bytes, 4);
    // Frame 1 holds the header as one raw zstd block after a 9-byte frame header and a 3-byte block header.
    const std::size_t header_at = test::at<std::uint32_t>(b, entries) + 12;  // after frame 0
    put_u64(b, header_at + 1, claimed_fibers);
    const std::string path = fx.write("claims.fftz", b);
    EXPECT_EQ(open_error(path), Errc::checksum);
    const test::PeakRun run = test::run_cli_peak({"verify", path});
    EXPECT_EQ(run.status, 7);
    if (!kSanitized) {
        EXPECT_LT(run.peak_mb, 64.0) << "MB peak for a file of a few kB";
    }
}

// A valid .fftz of 2^21 empty fibers (a few kB): opening and verifying it
// costs the LUT's 12 bytes a fiber plus a few for the index, nothing that
// grows with what the container's frames claim (it took 3.7 GB at 2^27).
TEST(TrailerIntegrity, ManyEmptyFibersCostTheirTablesOnly) {
    test::TempDir dir;
    const std::string tck = dir.file("empty.tck"), fftz = dir.file("empty.fftz");
    constexpr std::uint64_t kFibers = std::uint64_t{1} << 21;
    {
        TckWriter w(tck, {}, true);
        w.write(std::vector<Vec3f>{{1, 2, 3}, {1.1f, 2, 3}});
        for (std::uint64_t i = 1; i < kFibers; ++i) w.write(std::vector<Vec3f>{});
        w.finish();
    }
    CompressOptions o;
    o.zstd = ZstdOptions{};
    compress_file(tck, fftz, o);
    ASSERT_LT(std::filesystem::file_size(fftz), 64u << 10);
    for (const char* command : {"info", "verify"}) {
        const test::PeakRun run = test::run_cli_peak({command, fftz});
        EXPECT_EQ(run.status, 0) << command;
        const double mb = run.peak_mb, tables_mb = 12.0 * double(kFibers) / (1 << 20);
        if (!kSanitized) {
            EXPECT_LT(mb, tables_mb + 6.0 * double(kFibers) / (1 << 20) + 16) << command;
        }
    }
}

// The sweep: every single-bit flip of a small file (header, LUT, blocks,
// every trailer chunk, footer) is either caught by verify or harmless.
TEST(TrailerIntegrity, NoSingleBitFlipPassesVerifyAndChangesTheFile) {
    Fixture fx(6);
    const Decoded original = *decoded(fx.fft);
    const std::string path = fx.dir.file("flip.fft");
    std::size_t detected = 0, harmless = 0;
    // Where the harmless flips are, by part of the file (for the record).
    const std::vector<Chunk> chunks = walk_trailer(fx.bytes, fx.header.file_bytes());
    auto part = [&](std::size_t byte) -> std::string {
        if (byte < fx.header.lut_offset()) return "header";
        if (byte < fx.header.blocks_offset()) return "LUT";
        if (byte < fx.header.file_bytes()) return "blocks";
        for (const Chunk& c : chunks)
            if (byte < c.at + c.size) return c.tag;
        return "footer";
    };
    std::map<std::string, int> harmless_in;
    for (std::size_t byte = 0; byte < fx.bytes.size(); ++byte) {
        for (int bit = 0; bit < 8; ++bit) {
            std::string b = fx.bytes;
            b[byte] = char(std::uint8_t(b[byte]) ^ (1u << bit));
            test::write_file(path, b);
            if (verify_error(path)) {
                ++detected;
                continue;
            }
            const auto got = decoded(path);
            ASSERT_TRUE(got && *got == original) << "byte " << byte << " bit " << bit << " of " << fx.bytes.size()
                                                 << ": verify passed, the decoded file changed";
            ++harmless;
            ++harmless_in[part(byte)];
        }
    }
    RecordProperty("flips", int(8 * fx.bytes.size()));
    RecordProperty("detected", int(detected));
    EXPECT_EQ(detected + harmless, 8 * fx.bytes.size());
    std::printf("single-bit flips over %zu bytes: %zu detected, %zu harmless (decode unchanged)", fx.bytes.size(),
                detected, harmless);
    for (const auto& [where, n] : harmless_in) std::printf(", %d in %s", n, where.c_str());
    std::printf("\n");
}
