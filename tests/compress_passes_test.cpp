// compress reads its input in two or three passes (issue 12, class 9): an
// input edited or replaced between them makes compress fail with a clear
// error, instead of writing a file whose passes disagree (one that verify
// rejects, or worse, one that decodes to other points).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>

#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

using namespace fiblet;
namespace fs = std::filesystem;

namespace {

// 3000 short fibers: the scan reports progress (every 1024 fibers) mid-pass.
void write_tck(const std::string& path) {
    TckWriter w(path, {}, true);
    std::vector<Vec3f> f(20);
    for (int i = 0; i < 3000; ++i) {
        for (std::size_t k = 0; k < f.size(); ++k) f[k] = {0.1f * float(k), 0.01f * float(i), 1.0f};
        w.write(f);
    }
    w.finish();
}

// Compresses `in` to `out`, running `edit` once, during the first pass (the
// progress callback is the hook: it runs between reads). Returns the error.
std::string compress_editing(const std::string& in, const std::string& out, const std::function<void()>& edit) {
    CompressOptions o;
    bool done = false;
    o.progress = [&](const char* phase, double) {
        if (!done && std::strcmp(phase, "scan") == 0) edit(), done = true;
    };
    try {
        compress_file(in, out, o);
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), Errc::io) << e.what();
        return e.what();
    }
    return "no error";
}

// Overwrites 4 bytes in place near the end of the data (a coordinate), size unchanged.
void poke(const std::string& path, bool keep_mtime) {
    struct stat st {};
    ASSERT_EQ(::stat(path.c_str(), &st), 0);
    const int fd = ::open(path.c_str(), O_WRONLY);
    ASSERT_GE(fd, 0);
    const float v = 7.5f;
    ASSERT_EQ(::pwrite(fd, &v, 4, st.st_size - 100), 4);
    ::close(fd);
    if (keep_mtime) {  // an edit the size and time checks cannot see: only the bytes differ
        const struct timespec times[2] = {st.st_atim, st.st_mtim};
        ASSERT_EQ(::utimensat(AT_FDCWD, path.c_str(), times, 0), 0);
    }
}

}  // namespace

TEST(CompressPasses, AnInputEditedInPlaceIsRefused) {
    for (bool keep_mtime : {false, true}) {
        test::TempDir dir;
        write_tck(dir.file("in.tck"));
        const std::string what = compress_editing(dir.file("in.tck"), dir.file("out.fft"),
                                                  [&] { poke(dir.file("in.tck"), keep_mtime); });
        EXPECT_NE(what.find("changed while it was being read"), std::string::npos) << what;
        EXPECT_NE(what.find(keep_mtime ? "other bytes" : "modification time"), std::string::npos) << what;
        EXPECT_FALSE(fs::exists(dir.file("out.fft")));
        EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
    }
}

TEST(CompressPasses, AnInputReplacedOrGrownIsRefused) {
    test::TempDir dir;
    write_tck(dir.file("in.tck"));
    test::write_three_fiber_tck(dir.file("other.tck"));
    std::string what = compress_editing(dir.file("in.tck"), dir.file("out.fft"),
                                        [&] { fs::rename(dir.file("other.tck"), dir.file("in.tck")); });
    EXPECT_NE(what.find("another file now has its name"), std::string::npos) << what;
    EXPECT_FALSE(fs::exists(dir.file("out.fft")));

    write_tck(dir.file("grown.tck"));
    what = compress_editing(dir.file("grown.tck"), dir.file("out.fft"), [&] {
        std::FILE* f = std::fopen(dir.file("grown.tck").c_str(), "ab");
        std::fputs("appended", f);
        std::fclose(f);
    });
    EXPECT_NE(what.find("changed while it was being read"), std::string::npos) << what;
    EXPECT_FALSE(fs::exists(dir.file("out.fft")));
}

TEST(CompressPasses, AnUntouchedInputCompressesAsBefore) {
    test::TempDir dir;
    write_tck(dir.file("in.tck"));
    EXPECT_EQ(compress_editing(dir.file("in.tck"), dir.file("out.fft"), [] {}), "no error");
    EXPECT_TRUE(fs::exists(dir.file("out.fft")));
}

TEST(CompressPasses, AnInputCutWhileReadIsNamedAsChangedNotAsTruncated) {
    test::TempDir dir;
    write_tck(dir.file("in.tck"));
    TckReader reader(dir.file("in.tck"), {.chunk_bytes = 4096});  // many reads: the cut lands between two
    std::vector<Vec3f> fiber;
    ASSERT_TRUE(reader.next(fiber));
    fs::resize_file(dir.file("in.tck"), fs::file_size(dir.file("in.tck")) / 2);
    try {
        while (reader.next(fiber)) {
        }
        FAIL() << "read to the end of a file cut in half";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), Errc::io) << e.what();
        EXPECT_NE(std::string(e.what()).find("changed while it was being read"), std::string::npos) << e.what();
    }
}

// The report times each stage (CompressTimings: what --json prints as
// "timings"). On one thread the stages do not overlap: their sum is at most
// the run's time, and every stage that has work to do takes some.
TEST(CompressPasses, TheStagesAreTimedWithinTheRunsTime) {
    test::TempDir dir;
    write_tck(dir.file("in.tck"));
    CompressOptions o;
    o.threads = 1;
    const CompressReport r = compress_file(dir.file("in.tck"), dir.file("out.fft"), o);
    const CompressTimings& t = r.timings;
    for (const double s : {t.read, t.scan, t.tune, t.encode, t.metrics, t.index, t.write}) EXPECT_GT(s, 0.0);
    EXPECT_LE(t.total(), r.seconds);
    // No index asked: no time in it.
    o.block_index = false;
    o.overwrite = true;
    EXPECT_EQ(compress_file(dir.file("in.tck"), dir.file("out.fft"), o).timings.index, 0.0);
}
