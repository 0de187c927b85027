// Decoding across threads: the output never depends on the number of
// threads or on the chunking (same points, same order, same offsets), the
// caller-provided buffers are filled exactly and never overrun, and errors
// found by a worker thread reach the caller.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "sdstream_file.hpp"
#include "test_util.hpp"

using namespace fiblet;

namespace {

class DecodeThreads : public test::SdstreamFile {
protected:
    static DecodeOptions options(unsigned threads, std::size_t chunk_blocks = 1u << 16, const char* decoder = "auto") {
        DecodeOptions o;
        o.threads = threads;
        o.chunk_blocks = chunk_blocks;
        o.decoder = parse_decoder(decoder);
        return o;
    }
};

bool same(const Streamlines& a, const Streamlines& b) {
    return a.offsets == b.offsets && a.xyz.size() == b.xyz.size() &&
           std::memcmp(a.xyz.data(), b.xyz.data(), 4 * a.xyz.size()) == 0;
}

}  // namespace

TEST_F(DecodeThreads, DecodeBlocksGivesTheSameBitsWithAnyThreadCount) {
    const FftFile file(path_);
    const DecodeContext ctx(file.header());
    const std::vector<std::uint8_t> blocks = file.read_blocks(0, file.header().blocks);
    ASSERT_GE(file.header().blocks, 4u * 2048u);  // four threads get work
    const std::size_t points = file.header().points;
    for (const char* name : {"auto", "scalar", "warp"}) {
        std::vector<float> one(3 * points), many(3 * points);
        ASSERT_EQ(decode_blocks(ctx, blocks.data(), file.header().blocks, one.data(), parse_decoder(name), 1), points);
        for (unsigned threads : {2u, 3u, 4u, 0u}) {
            std::fill(many.begin(), many.end(), -1.0f);
            ASSERT_EQ(decode_blocks(ctx, blocks.data(), file.header().blocks, many.data(), parse_decoder(name), threads),
                      points);
            EXPECT_EQ(std::memcmp(one.data(), many.data(), 12 * points), 0) << name << " threads " << threads;
        }
    }
}

TEST_F(DecodeThreads, FibersDecodeTheSameWithAnyThreadsAndChunks) {
    const FftFile file(path_);
    const std::uint64_t fibers = file.header().fibers;
    const Streamlines reference = decode_fibers(file, 0, fibers, options(1, 1u << 16, "scalar"));
    ASSERT_EQ(reference.size(), fibers);
    ASSERT_EQ(reference.point_count(), file.header().points);
    for (unsigned threads : {1u, 2u, 3u, 0u})
        for (std::size_t chunk : {std::size_t(1), std::size_t(7), std::size_t(5000), std::size_t(1) << 16}) {
            EXPECT_TRUE(same(decode_fibers(file, 0, fibers, options(threads, chunk)), reference))
                << "threads " << threads << " chunk " << chunk;
        }
    // A range in the middle: the slice of the whole.
    const std::uint64_t begin = fibers / 3, end = 2 * fibers / 3;
    const Streamlines part = decode_fibers(file, begin, end, options(2, 5000));
    ASSERT_EQ(part.size(), end - begin);
    const std::uint64_t first = reference.offsets[begin];
    for (std::uint64_t i = 0; i <= end - begin; ++i) ASSERT_EQ(part.offsets[i], reference.offsets[begin + i] - first);
    EXPECT_EQ(std::memcmp(part.xyz.data(), &reference.xyz[3 * first], 4 * part.xyz.size()), 0);
}

TEST_F(DecodeThreads, DecodeFileStreamsWholeFibersInOrder) {
    const FftFile file(path_);
    const std::uint64_t fibers = file.header().fibers;
    const Streamlines whole = decode_fibers(file, 0, fibers, options(1));
    for (unsigned threads : {1u, 2u, 4u}) {
        Streamlines joined;
        std::uint64_t next = 0, chunks = 0;
        decode_file(
            file,
            [&](std::uint64_t first, const Streamlines& chunk) {
                EXPECT_EQ(first, next);
                next += chunk.size();
                ++chunks;
                for (std::size_t i = 0; i < chunk.size(); ++i)
                    joined.offsets.push_back(joined.offsets.back() + (chunk.offsets[i + 1] - chunk.offsets[i]));
                joined.xyz.insert(joined.xyz.end(), chunk.xyz.begin(), chunk.xyz.end());
            },
            options(threads, 4200));  // two runs of 2048+ blocks per chunk
        EXPECT_EQ(next, fibers);
        EXPECT_GE(chunks, 3u);
        EXPECT_TRUE(same(joined, whole)) << "threads " << threads;
    }
}

TEST_F(DecodeThreads, DecodeIntoFillsTheCallersBuffersExactly) {
    const FftFile file(path_);
    const std::uint64_t fibers = file.header().fibers, points = file.header().points;
    const Streamlines whole = decode_fibers(file, 0, fibers, options(1));
    const float sentinel = 7777.0f;
    std::vector<float> xyz(3 * points + 16, sentinel);
    std::vector<std::uint64_t> offsets(fibers + 1, ~0ull);
    // Any threads and parts (of 1 and 7 blocks: every part waits for the
    // one before it to place its points).
    for (unsigned threads : {1u, 2u, 3u})
        for (std::size_t part : {std::size_t(1), std::size_t(7), std::size_t(5000), std::size_t(0)}) {
            std::fill(xyz.begin(), xyz.end(), sentinel);
            std::fill(offsets.begin(), offsets.end(), ~0ull);
            EXPECT_EQ(decode_fibers_into(file, 0, fibers, xyz, offsets, options(threads, part)), points);
            EXPECT_EQ(offsets, whole.offsets) << "threads " << threads << " part " << part;
            EXPECT_EQ(std::memcmp(xyz.data(), whole.xyz.data(), 12 * points), 0) << "threads " << threads << " part " << part;
            for (std::size_t i = 3 * points; i < xyz.size(); ++i) ASSERT_EQ(xyz[i], sentinel);
        }

    // One point short: refused, and nothing written past the buffer.
    std::vector<float> small(3 * (points - 1) + 16, sentinel);
    try {
        decode_fibers_into(file, 0, fibers, std::span<float>(small.data(), 3 * (points - 1)), offsets, options(2, 5000));
        ADD_FAILURE() << "a buffer one point short was accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), Errc::invalid_argument);
    }
    for (std::size_t i = 3 * (points - 1); i < small.size(); ++i) ASSERT_EQ(small[i], sentinel);
    std::vector<std::uint64_t> few(fibers);
    EXPECT_THROW(decode_fibers_into(file, 0, fibers, xyz, few, options(1)), Error);
    EXPECT_THROW(decode_fibers(file, 1, fibers + 1, options(1)), Error);
}

TEST_F(DecodeThreads, ABadBlockFoundByAWorkerThreadIsReported) {
    // Copy the file and give a block a point count of 0: in the last
    // thread's run, and (decode_fibers_into) in the first part, which the
    // parts after it wait for.
    const FftFile good(path_);
    const FftHeader& h = good.header();
    for (const std::uint64_t block : {std::uint64_t{h.blocks - 10}, std::uint64_t{10}}) {
        const std::string bad = dir_->file("bad.fft");
        std::string bytes = test::read_file(path_);
        bytes[h.blocks_offset() + block * h.block_bytes() + kBlockFlagsOffset] = char(0);
        test::write_file(bad, bytes);
        const FftFile file(bad);
        // Without the checksums, only the part holding the block finds it.
        const FftFile unchecked(bad, {.verify_checksums = false});
        std::vector<float> xyz(3 * std::uint64_t(h.blocks) * h.points_per_block);
        std::vector<std::uint64_t> offsets(h.fibers + 1);
        for (unsigned threads : {1u, 2u, 3u}) {
            EXPECT_EQ(test::error_of([&] { decode_fibers(file, 0, h.fibers, options(threads)); }), Errc::fft_format)
                << "block " << block << ", threads " << threads;
            for (const FftFile* f : {&file, &unchecked})
                EXPECT_EQ(test::error_of([&] { decode_fibers_into(*f, 0, h.fibers, xyz, offsets, options(threads, 1000)); }),
                          Errc::fft_format)
                    << "block " << block << ", threads " << threads;
        }
    }
}

namespace {

int run_cli(const std::string& args) {
    const int st = std::system((std::string(FIBLET_CLI) + " " + args + " >/dev/null 2>&1").c_str());
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

}  // namespace

TEST_F(DecodeThreads, CliDecompressTakesThreadsAndDecoder) {
    const std::string a = dir_->file("a.tck"), b = dir_->file("b.tck"), c = dir_->file("c.tck");
    ASSERT_EQ(run_cli("decompress " + path_ + " -o " + a + " -j 1 --decoder scalar"), 0);
    ASSERT_EQ(run_cli("decompress " + path_ + " -o " + b + " --threads 3 --decoder auto"), 0);
    ASSERT_EQ(run_cli("decompress " + path_ + " -o " + c + " -j 2 --decoder warp-portable"), 0);
    // The default decoder is bit-identical to the reference, whatever the threads.
    EXPECT_EQ(test::read_file(a), test::read_file(b));
    EXPECT_EQ(test::read_file(a).size(), test::read_file(c).size());
    EXPECT_EQ(run_cli("decompress " + path_ + " -o " + dir_->file("d.tck") + " --decoder fastest"), 2);
    EXPECT_FALSE(std::filesystem::exists(dir_->file("d.tck")));
}
