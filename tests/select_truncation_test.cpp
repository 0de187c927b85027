// A .fft truncated by another process while it is being read (issue 12,
// class 6): selection reads blocks with pread by default, so it fails with a
// clear Error instead of dying of SIGBUS in a memory mapping, and an output
// being written is cleaned up (no temporary, no output).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "fiblet/block_index.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/fft_subset.hpp"
#include "fiblet/select.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

using namespace fiblet;
namespace fs = std::filesystem;

namespace {

// 400 curved fibers of 300 points: a few thousand blocks, several checksum groups.
void write_tractogram(const std::string& path) {
    TckWriter w(path, {}, true);
    std::vector<Vec3f> f(300);
    for (int i = 0; i < 400; ++i) {
        for (std::size_t k = 0; k < f.size(); ++k) {
            const float t = 0.02f * float(k);
            f[k] = {10 * std::cos(t + float(i)), 10 * std::sin(t + float(i)), 0.1f * float(k) + 0.01f * float(i)};
        }
        w.write(f);
    }
    w.finish();
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

TEST(SelectTruncation, ATruncatedFileIsAnErrorNotACrash) {
    test::TempDir dir;
    write_tractogram(dir.file("in.tck"));
    compress_file(dir.file("in.tck"), dir.file("in.fft"), {});
    TruncatedAfterOpen t(dir.file("in.fft"));
    t.cut();
    Query everything;  // reads the blocks past the cut
    try {
        select(t.file, t.index, everything, [](const SelectedChunk&) {});
        FAIL() << "selection over a truncated file succeeded";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), Errc::fft_format) << e.what();
        EXPECT_NE(std::string(e.what()).find("unexpected end of file"), std::string::npos) << e.what();
    }
}

TEST(SelectTruncation, ASubsetBeingWrittenIsRemoved) {
    test::TempDir dir;
    write_tractogram(dir.file("in.tck"));
    compress_file(dir.file("in.tck"), dir.file("in.fft"), {});
    fs::create_directory(dir.file("out"));
    TruncatedAfterOpen t(dir.file("in.fft"));
    const auto runs = select_runs(t.file, t.index, Query{});
    t.cut();
    EXPECT_THROW(write_fft_subset(t.file, runs, dir.file("out/subset.fft"), false), Error);
    EXPECT_TRUE(fs::is_empty(dir.file("out")));  // neither the output nor its temporary
}
