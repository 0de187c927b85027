// A .fft truncated by another process while it is being read (issue 12,
// class 6): selection fails with a clear Error, whether it copies blocks out
// of a memory mapping (the default: the copy catches the SIGBUS) or reads
// them with pread, and an output being written is cleaned up (no temporary,
// no output). A SIGBUS outside those copies still goes where it went before.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "fiblet/block_index.hpp"
#include "fiblet/checksum.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/fft_subset.hpp"
#include "fiblet/select.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

using namespace fiblet;
namespace fs = std::filesystem;

// AddressSanitizer builds (FIBLET_SANITIZE=ON): ASan takes SIGBUS itself by
// default (a report, then exit 1), so a fault outside fiblet's copies would
// end in ASan's report, not in the disposition these tests check; this
// binary leaves SIGBUS to the process, as a program without ASan has it.
// Only ASan's runtime calls this; other builds never do.
extern "C" __attribute__((used, visibility("default"))) const char* __asan_default_options() {
    return "handle_sigbus=0";
}

namespace {

// 400 helices of 300 points: a few thousand blocks, several checksum groups.
std::string compressed_helices(const test::TempDir& dir) {
    test::write_helix_tck(dir.file("in.tck"), 400, 300);
    compress_file(dir.file("in.tck"), dir.file("in.fft"), {});
    return dir.file("in.fft");
}

// The file opened (header, LUT, index), then cut to half of its blocks by
// cut(): another process's truncate between open and read, as the CLI meets it.
struct TruncatedAfterOpen {
    explicit TruncatedAfterOpen(const std::string& path) : file(path), index(BlockIndex::load(file)) {}
    void cut() const {
        const FftHeader& h = file.header();
        EXPECT_GT(h.blocks, 100u);
        EXPECT_EQ(::truncate(file.path().c_str(), off_t(h.blocks_offset() + h.blocks / 2 * h.block_bytes())), 0);
    }
    FftFile file;
    BlockIndex index;
};

}  // namespace

void expect_unexpected_end(const std::function<void()>& read, const std::string& what) {
    try {
        read();
        ADD_FAILURE() << what << ": reading a truncated file succeeded";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), Errc::fft_format) << what << ": " << e.what();
        EXPECT_NE(std::string(e.what()).find("unexpected end of file"), std::string::npos) << what << ": " << e.what();
    }
}

TEST(SelectTruncation, ATruncatedFileIsAnErrorNotACrash) {
    for (const bool mapped : {true, false}) {
        test::TempDir dir;
        TruncatedAfterOpen t(compressed_helices(dir));
        t.cut();
        SelectOptions o;
        o.map_file = mapped;
        Query everything;  // reads the blocks past the cut
        expect_unexpected_end([&] { select(t.file, t.index, everything, [](const SelectedChunk&) {}, o); },
                              mapped ? "mapped" : "pread");
    }
}

// The mapping made by a first query, the file cut, a second query: its
// copies fault (SIGBUS) on the pages past the new end, and fail.
TEST(SelectTruncation, AFileCutUnderAnExistingMappingIsAnError) {
    test::TempDir dir;
    TruncatedAfterOpen t(compressed_helices(dir));
    std::uint64_t points = 0;
    select(t.file, t.index, Query{}, [&](const SelectedChunk& c) { points += c.point_count(); });
    EXPECT_EQ(points, t.file.header().points);
    t.cut();
    expect_unexpected_end([&] { select(t.file, t.index, Query{}, [](const SelectedChunk&) {}); }, "second query");
    // The blocks before the cut still read, through the same mapping.
    const FftFile::BlockSpan first{0, 4};
    std::vector<std::uint8_t> blocks(4 * t.file.header().block_bytes());
    EXPECT_TRUE(t.file.read_blocks_mapped({&first, 1}, blocks.data()));
    EXPECT_EQ(blocks, t.file.read_blocks(0, 4));
}

// A block before the cut whose checksum group reaches past it: hashing the
// group's unread part (in place in the mapping) meets the cut, read or mapped.
TEST(SelectTruncation, AGroupHashedAcrossTheCutIsAnError) {
    for (const bool mapped : {true, false}) {
        test::TempDir dir;
        TruncatedAfterOpen t(compressed_helices(dir));
        t.cut();
        const std::uint64_t last_kept = t.file.header().blocks / 2 - 1;
        ASSERT_NE((last_kept + 1) % kDefaultChecksumGroupBlocks, 0u);  // its group goes on past the cut
        std::vector<std::uint8_t> block(t.file.header().block_bytes());
        const FftFile::BlockSpan span{last_kept, 1};
        expect_unexpected_end(
            [&] { mapped ? (void)t.file.read_blocks_mapped({&span, 1}, block.data()) : t.file.read_blocks(last_kept, 1, block.data()); },
            mapped ? "mapped" : "read");
    }
}

// The first block past the cut, on the page the cut falls in: the mapping
// reads zeros there (no fault), which must not pass for a damaged block.
TEST(SelectTruncation, ABlockPastACutInsideAPageIsAnError) {
    test::TempDir dir;
    TruncatedAfterOpen t(compressed_helices(dir));
    t.cut();
    const FftHeader& h = t.file.header();
    const std::uint64_t first_cut = h.blocks / 2, page = std::uint64_t(::sysconf(_SC_PAGESIZE));
    const std::uint64_t cut_at = h.blocks_offset() + first_cut * h.block_bytes();
    ASSERT_LT(cut_at % page + h.block_bytes(), page);  // the block lies inside the cut page
    std::vector<std::uint8_t> block(h.block_bytes());
    const FftFile::BlockSpan span{first_cut, 1};
    expect_unexpected_end([&] { t.file.read_blocks_mapped({&span, 1}, block.data()); }, "mapped");
}

// A mapped page past the end of a truncated file, read outside fiblet's
// copies: SIGBUS as without fiblet, to the handler from before if any.
// The death test's child made `dir` (it reruns the test) and never returns:
// it removes the directory once the file is mapped and open.
void fault_outside_fiblet(const std::string& path, const std::string& dir) {
    const int fd = ::open(path.c_str(), O_RDONLY), writable = ::open(path.c_str(), O_WRONLY);
    const long page = ::sysconf(_SC_PAGESIZE);
    auto* p = static_cast<volatile const char*>(::mmap(nullptr, 4 * page, PROT_READ, MAP_SHARED, fd, 0));
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
    if (p == MAP_FAILED || ::ftruncate(writable, page) != 0) std::_Exit(3);
    (void)p[3 * page];
    std::_Exit(0);  // not reached: the read faults
}

// fiblet's SIGBUS handler, installed by a first mapped selection.
void install_fiblet_handler(const std::string& fft) {
    const FftFile f(fft);
    select(f, BlockIndex::load(f), Query{}, [](const SelectedChunk&) {});
}

// A .fft to select from and a file of four pages to fault on.
struct FaultFiles {
    test::TempDir dir;
    std::string fft = compressed_helices(dir), victim = dir.file("victim");
    FaultFiles() { test::write_file(victim, std::string(std::size_t(4 * ::sysconf(_SC_PAGESIZE)), '\1')); }
};

TEST(SelectTruncationDeathTest, AFaultOutsideACopyStillEndsTheProcess) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");  // a fresh process: no handler of an earlier test
    const FaultFiles files;
    EXPECT_EXIT(
        {
            install_fiblet_handler(files.fft);
            fault_outside_fiblet(files.victim, files.dir.path());
        },
        ::testing::KilledBySignal(SIGBUS), "");
}

TEST(SelectTruncationDeathTest, AFaultOutsideACopyGoesToTheHandlerFromBefore) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");  // a fresh process: its handler is installed before fiblet's
    const FaultFiles files;
    EXPECT_EXIT(
        {
            struct sigaction a {};
            a.sa_handler = [](int) { std::_Exit(42); };
            ::sigaction(SIGBUS, &a, nullptr);
            install_fiblet_handler(files.fft);
            fault_outside_fiblet(files.victim, files.dir.path());
        },
        ::testing::ExitedWithCode(42), "");
}

TEST(SelectTruncation, ASubsetBeingWrittenIsRemoved) {
    test::TempDir dir;
    fs::create_directory(dir.file("out"));
    TruncatedAfterOpen t(compressed_helices(dir));
    const auto runs = select_runs(t.file, t.index, Query{});
    t.cut();
    EXPECT_THROW(write_fft_subset(t.file, runs, dir.file("out/subset.fft"), false), Error);
    EXPECT_TRUE(fs::is_empty(dir.file("out")));  // neither the output nor its temporary
}
