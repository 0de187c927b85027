// The worker pool and the pipelines on it (fiblet/parallel.hpp): every task
// runs exactly once whatever the thread count, errors reach the caller (of
// parts published in order, the first failed part's),
// nested and overlapping jobs finish, a wait that runs the next job
// meanwhile keeps the two jobs' errors apart; compression writes the same bytes with
// 1 or N threads (fixed-step and resampled input, with and without zstd),
// a pipelined decode_file (overlap_sink) hands the sink the same chunks as
// a serial one, its errors reaching the caller, and a .tck written a chunk
// at a time (writev) holds the same bytes as one written fiber by fiber.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <filesystem>
#include <limits>
#include <span>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "fiblet/compress.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/parallel.hpp"
#include "fiblet/tck.hpp"
#include "core/ordered_ends.hpp"
#include "test_util.hpp"

using namespace fiblet;

TEST(WorkerPool, EveryTaskRunsOnceWithAnyThreadCount) {
    for (unsigned threads : {1u, 2u, 3u, 8u, 0u})
        for (std::size_t n : {std::size_t(0), std::size_t(1), std::size_t(5), std::size_t(1000)}) {
            std::vector<std::atomic<int>> runs(n);
            parallel_for(n, threads, [&](std::size_t i) { runs[i].fetch_add(1); });
            for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(runs[i].load(), 1) << "threads " << threads << " task " << i;
        }
}

TEST(WorkerPool, ATaskExceptionReachesTheCallerAfterTheOthersFinish) {
    for (unsigned threads : {1u, 2u, 4u}) {
        std::atomic<int> running{0}, finished{0};
        try {
            parallel_for(64, threads, [&](std::size_t i) {
                ++running;
                if (i == 17) throw Error(Errc::fft_format, "task 17");
                ++finished;
                --running;
            });
            ADD_FAILURE() << "no exception";
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), Errc::fft_format);
            EXPECT_STREQ(e.what(), "task 17");
        }
        EXPECT_EQ(running.load(), 1);  // only the failed task: none still running
        EXPECT_LT(finished.load(), 64);
    }
}

TEST(WorkerPool, NestedAndOverlappingJobsFinish) {
    // Every worker busy with an outer task that starts an inner job: the
    // callers take their inner tasks themselves.
    std::atomic<std::uint64_t> sum{0};
    parallel_for(8, 4, [&](std::size_t i) {
        parallel_for(100, 4, [&](std::size_t j) { sum += i * 100 + j; });
    });
    EXPECT_EQ(sum.load(), (799ull * 800ull) / 2);
    // A background job while the caller works, then waits.
    std::vector<int> out(500, 0);
    {
        ParallelJob job(out.size(), 2, [&](std::size_t i) { out[i] = int(i) * 2; });
        parallel_for(10, 2, [](std::size_t) {});
        job.wait();
    }
    for (std::size_t i = 0; i < out.size(); ++i) ASSERT_EQ(out[i], int(i) * 2);
    // Destroyed without wait(): still waits for its tasks.
    std::atomic<int> n{0};
    { ParallelJob job(100, 3, [&](std::size_t) { ++n; }); }
    EXPECT_EQ(n.load(), 100);
}

TEST(WorkerPool, WaitRunsTheNextJobMeanwhileAndKeepsErrorsApart) {
    // wait(&next) returns once its own job is done, whatever of `next` the
    // caller ran meanwhile; next's tasks each run once, and the failure of
    // one of them (run by either thread) reaches next.wait(), not wait().
    for (unsigned threads : {1u, 2u, 3u}) {
        std::vector<std::atomic<int>> first(4), second(200);
        ParallelJob a(first.size(), threads, [&](std::size_t i) {
            if (i == 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));  // one slow task
            first[i].fetch_add(1);
        });
        ParallelJob b(second.size(), threads, [&](std::size_t i) {
            second[i].fetch_add(1);
            if (i == 3) throw Error(Errc::io, "task 3 of the next job");
        });
        EXPECT_NO_THROW(a.wait(&b)) << "threads " << threads;
        for (std::size_t i = 0; i < first.size(); ++i) ASSERT_EQ(first[i].load(), 1) << "threads " << threads;
        try {
            b.wait();
            ADD_FAILURE() << "no exception, threads " << threads;
        } catch (const Error& e) {
            EXPECT_STREQ(e.what(), "task 3 of the next job");
        }
        for (std::size_t i = 0; i < second.size(); ++i) ASSERT_LE(second[i].load(), 1) << "threads " << threads;
        EXPECT_EQ(second[3].load(), 1);
    }
}

namespace {

std::string compressed(const std::string& tck, const std::string& out, unsigned threads, bool zstd = false) {
    CompressOptions o;
    o.threads = threads;
    o.overwrite = true;
    if (zstd) o.zstd = ZstdOptions{.level = 3};
    compress_file(tck, out, o);
    return test::read_file(out);
}

}  // namespace

// Parts publishing their outputs in order (detail::parallel_parts): a
// later part that fails first does not hide an earlier part's error, every
// part before the first failed one runs, the parts after it do not publish.
TEST(WorkerPool, ParallelPartsReportTheFirstFailedPartsError) {
    for (unsigned threads : {1u, 2u, 4u}) {
        constexpr std::size_t kParts = 12;
        detail::OrderedEnds ends(kParts);
        std::atomic<int> ran[kParts] = {};
        try {
            detail::parallel_parts(ends, threads, [&](std::size_t p) {
                ++ran[p];
                if (p == 7) throw std::runtime_error("part 7");  // at once
                if (p == 3) {
                    std::this_thread::sleep_for(std::chrono::milliseconds(30));
                    throw std::runtime_error("part 3");  // later, but earlier in order
                }
                ends.publish(p, 10);
            });
            ADD_FAILURE() << "no error reached the caller";
        } catch (const std::runtime_error& e) {
            EXPECT_STREQ(e.what(), "part 3") << threads << " threads";
        }
        for (std::size_t p = 0; p <= 3; ++p) EXPECT_EQ(ran[p].load(), 1) << p;
        EXPECT_EQ(ends.end(), detail::OrderedEnds::kFailed);
    }
}

TEST(CompressThreads, TheSameBytesWithAnyThreadCount) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    // Fixed step (scan, encode), variable step (resample scan, resampled
    // encode), and fibers whose ends are placed again within the batch's
    // error once its tasks are done (compress_encode.cpp, finish_batch).
    for (const char* name : {"small-sdstream.tck", "small-ifod2.tck", "bundles/cingulum-1-step0.1.tck"}) {
        const std::string tck = test::shared_data(name);
        const std::string one = compressed(tck, dir.file("one.fft"), 1);
        ASSERT_GT(one.size(), 1000u);
        for (unsigned threads : {2u, 3u, 0u})
            EXPECT_TRUE(compressed(tck, dir.file("many.fft"), threads) == one) << name << " threads " << threads;
    }
    const std::string tck = test::shared_data("small-ifod2.tck");
    EXPECT_TRUE(compressed(tck, dir.file("z1.fftz"), 1, true) == compressed(tck, dir.file("z2.fftz"), 2, true));
}

TEST(DecodePipeline, OverlappedSinkGetsTheSameChunksInOrder) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    test::TempDir dir;
    const std::string path = dir.file("s.fft");
    CompressOptions co;
    co.direction_bits = 8;  // 14,736 blocks: five chunks (16 bits, the default here, has 3,937)
    compress_file(test::shared_data("small-sdstream.tck"), path, co);
    const FftFile file(path);
    auto run = [&](bool overlap, unsigned threads) {
        DecodeOptions o;
        o.threads = threads;
        o.chunk_blocks = 3000;
        o.overlap_sink = overlap;
        std::vector<std::pair<std::uint64_t, Streamlines>> chunks;
        decode_file(file, [&](std::uint64_t first, const Streamlines& c) { chunks.emplace_back(first, c); }, o);
        return chunks;
    };
    const auto serial = run(false, 1);
    ASSERT_GE(serial.size(), 3u);
    for (unsigned threads : {1u, 2u, 3u}) {
        const auto piped = run(true, threads);
        ASSERT_EQ(piped.size(), serial.size()) << threads;
        for (std::size_t i = 0; i < serial.size(); ++i) {
            EXPECT_EQ(piped[i].first, serial[i].first);
            EXPECT_EQ(piped[i].second.offsets, serial[i].second.offsets);
            ASSERT_EQ(piped[i].second.xyz.size(), serial[i].second.xyz.size());
            EXPECT_EQ(std::memcmp(piped[i].second.xyz.data(), serial[i].second.xyz.data(), 4 * serial[i].second.xyz.size()),
                      0);
        }
    }
    // The sink's error reaches the caller, and nothing after it is sunk.
    DecodeOptions o;
    o.chunk_blocks = 3000;
    o.overlap_sink = true;
    int calls = 0;
    try {
        decode_file(file, [&](std::uint64_t, const Streamlines&) {
            if (++calls == 2) throw Error(Errc::io, "disk full");
        }, o);
        ADD_FAILURE() << "no exception";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), Errc::io);
    }
    EXPECT_EQ(calls, 2);
}

TEST(DecodePipeline, TckChunkWritesTheSameBytesAsFiberByFiber) {
    // More than 1024 pieces (writev's limit per call), empty fibers among them.
    test::TempDir dir;
    std::vector<float> xyz;
    std::vector<std::uint64_t> offsets{0};
    for (int f = 0; f < 1500; ++f) {
        const int n = f % 7 == 3 ? 0 : 1 + f % 5;
        for (int k = 0; k < 3 * n; ++k) xyz.push_back(float(f) + 0.25f * float(k));
        offsets.push_back(offsets.back() + std::uint64_t(n));
    }
    const std::string a = dir.file("a.tck"), b = dir.file("b.tck");
    {
        TckWriter w(a, {}, false);
        for (std::size_t i = 0; i + 1 < offsets.size(); ++i) w.write(&xyz[3 * offsets[i]], offsets[i + 1] - offsets[i]);
        w.finish();
    }
    {
        TckWriter w(b, {}, false);
        w.write_chunk(xyz.data(), std::span<const std::uint64_t>(offsets).first(700));
        w.write_chunk(xyz.data(), std::span<const std::uint64_t>(offsets).subspan(699));
        w.finish();
    }
    EXPECT_EQ(test::read_file(a), test::read_file(b));
    {  // points proven finite (decodes_finite): the same bytes without the check
        TckWriter w(dir.file("f.tck"), {}, false);
        w.write_finite_chunk(xyz.data(), std::span<const std::uint64_t>(offsets).first(900));
        w.write_finite_chunk(xyz.data(), std::span<const std::uint64_t>(offsets).subspan(899));
        w.finish();
    }
    EXPECT_EQ(test::read_file(a), test::read_file(dir.file("f.tck")));
    // A non-finite coordinate is refused, naming the streamline; no output is left.
    xyz[3 * offsets[10] + 1] = std::numeric_limits<float>::infinity();
    const std::string c = dir.file("c.tck");
    try {
        TckWriter w(c, {}, false);
        w.write_chunk(xyz.data(), offsets);
        ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), Errc::invalid_input);
    }
    EXPECT_FALSE(std::filesystem::exists(c));
}
