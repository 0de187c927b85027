// What an output may be (issue 12, class 4): a device is written through,
// never replaced; a symlink is followed and its target replaced atomically;
// a FIFO is refused; no command's output replaces one of its inputs (the same
// file, through a symlink or a hard link), even with --force; any legal file
// name works despite the temporary's suffix.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <string>

#include "cli_runner.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/output_file.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

using namespace fiblet;
namespace fs = std::filesystem;

namespace {

using test::error_of;

void write_output(const std::string& path, bool overwrite, const std::string& bytes) {
    AtomicOutputFile out(path, overwrite);
    out.write(bytes.data(), bytes.size());
    out.commit();
}

bool is_char_device(const std::string& path) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0 && S_ISCHR(st.st_mode);
}

std::size_t entries(const std::string& dir) {
    return std::size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

}  // namespace

TEST(OutputTarget, ACharacterDeviceIsWrittenThroughNeverReplaced) {
    for (bool overwrite : {false, true}) {
        AtomicOutputFile out("/dev/null", overwrite);
        EXPECT_TRUE(out.writes_through());
        EXPECT_TRUE(out.temporary_path().empty());
        out.write("abc", 3);
        out.write_at("X", 1, 1);
        out.commit();
        EXPECT_TRUE(is_char_device("/dev/null"));
    }
    // A full device reports the failure instead of being swapped for a file.
    EXPECT_EQ(error_of([] {
                  AtomicOutputFile out("/dev/full", true);
                  out.write("abc", 3);
                  out.commit();
              }),
              Errc::io);
    EXPECT_TRUE(is_char_device("/dev/full"));
}

TEST(OutputTarget, ASymlinkIsFollowedAndStaysALink) {
    test::TempDir dir;
    test::write_file(dir.file("target.bin"), "old");
    fs::create_symlink("target.bin", dir.file("link.bin"));
    EXPECT_EQ(error_of([&] { write_output(dir.file("link.bin"), false, "new"); }), Errc::exists);
    write_output(dir.file("link.bin"), true, "new");
    EXPECT_TRUE(fs::is_symlink(dir.file("link.bin")));
    EXPECT_EQ(test::read_file(dir.file("target.bin")), "new");
    EXPECT_EQ(entries(dir.path()), 2u);  // no temporary left next to either
    // A dangling link has no target to write: refused, not replaced by a file.
    fs::create_symlink("missing.bin", dir.file("dangling.bin"));
    EXPECT_EQ(error_of([&] { write_output(dir.file("dangling.bin"), true, "x"); }), Errc::invalid_argument);
    EXPECT_TRUE(fs::is_symlink(dir.file("dangling.bin")));
}

TEST(OutputTarget, AFifoOrADirectoryIsRefusedAndKept) {
    test::TempDir dir;
    ASSERT_EQ(::mkfifo(dir.file("fifo").c_str(), 0600), 0);
    EXPECT_EQ(error_of([&] { write_output(dir.file("fifo"), true, "x"); }), Errc::invalid_argument);
    EXPECT_TRUE(fs::is_fifo(dir.file("fifo")));
    fs::create_directory(dir.file("sub"));
    EXPECT_EQ(error_of([&] { write_output(dir.file("sub"), true, "x"); }), Errc::invalid_argument);
    EXPECT_TRUE(fs::is_directory(dir.file("sub")));
}

TEST(OutputTarget, AnOpenInputIsNeverReplacedWhateverItsName) {
    test::TempDir dir;
    test::write_three_fiber_tck(dir.file("in.tck"));
    const std::string original = test::read_file(dir.file("in.tck"));
    fs::create_symlink("in.tck", dir.file("soft.tck"));
    fs::create_hard_link(dir.file("in.tck"), dir.file("hard.tck"));
    {
        TckReader reader(dir.file("in.tck"));
        for (const char* name : {"in.tck", "soft.tck", "hard.tck"})
            EXPECT_EQ(error_of([&] { write_output(dir.file(name), true, "x"); }), Errc::invalid_argument) << name;
    }
    EXPECT_EQ(test::read_file(dir.file("in.tck")), original);
    write_output(dir.file("hard.tck"), true, "x");  // no longer an input: replaced as asked
    EXPECT_EQ(test::read_file(dir.file("hard.tck")), "x");

    // The same for .fft inputs, and through the library's writers.
    compress_file(dir.file("in.tck"), dir.file("in.fft"), {});
    const std::string fft = test::read_file(dir.file("in.fft"));
    {
        const FftFile file(dir.file("in.fft"));
        EXPECT_EQ(error_of([&] { TckWriter w(dir.file("in.fft"), {}, true); }), Errc::invalid_argument);
    }
    CompressOptions o;
    o.overwrite = true;
    EXPECT_EQ(error_of([&] { compress_file(dir.file("in.tck"), dir.file("soft.tck"), o); }), Errc::invalid_argument);
    EXPECT_EQ(test::read_file(dir.file("in.tck")), original);
    EXPECT_EQ(test::read_file(dir.file("in.fft")), fft);
}

TEST(OutputTarget, TheCliRefusesInputAsOutputWithForce) {
    test::TempDir dir;
    test::write_three_fiber_tck(dir.file("in.tck"));
    ASSERT_EQ(test::run_cli("compress -q " + dir.file("in.tck") + " -o " + dir.file("in.fft")).status, 0);
    const std::string tck = test::read_file(dir.file("in.tck")), fft = test::read_file(dir.file("in.fft"));
    fs::create_symlink("in.fft", dir.file("link.fft"));
    fs::create_symlink("in.tck", dir.file("tck-link.fft"));  // a .fft name (compress refuses others) on the input
    fs::create_symlink("in.fft", dir.file("fft-link.tck"));  // and a .tck name (decompress refuses others)
    for (const std::string& args :
         {"decompress -q -f " + dir.file("in.fft") + " -o " + dir.file("fft-link.tck"),
          "decompress -q -f " + dir.file("link.fft") + " -o " + dir.file("fft-link.tck"),
          "extract -q -f " + dir.file("in.fft") + " -o " + dir.file("link.fft"),
          "compress -q -f " + dir.file("in.tck") + " -o " + dir.file("tck-link.fft")}) {
        const auto r = test::run_cli(args);
        EXPECT_EQ(r.status, 2) << args << "\n" << r.output;
        EXPECT_NE(r.output.find("is an input of this command"), std::string::npos) << r.output;
    }
    EXPECT_EQ(test::read_file(dir.file("in.tck")), tck);
    EXPECT_EQ(test::read_file(dir.file("in.fft")), fft);
    // -o /dev/null: decoded and discarded, /dev/null untouched (no --force needed).
    EXPECT_EQ(test::run_cli("decompress -q " + dir.file("in.fft") + " -o /dev/null").status, 0);
    EXPECT_TRUE(is_char_device("/dev/null"));
}

TEST(OutputTarget, AnyLegalNameWorksDespiteTheTemporarySuffix) {
    test::TempDir dir;
    const long name_max = ::pathconf(dir.path().c_str(), _PC_NAME_MAX);
    ASSERT_GT(name_max, 20);
    for (std::size_t n : {std::size_t(249), std::size_t(name_max)}) {
        const std::string path = dir.file(std::string(n - 4, 'a') + ".fft");
        AtomicOutputFile out(path, false);
        EXPECT_LE(fs::path(out.temporary_path()).filename().string().size(), std::size_t(name_max));
        EXPECT_NE(out.temporary_path().find(".tmp-"), std::string::npos);  // still what cleanup globs match
        out.write("x", 1);
        out.commit();
        EXPECT_EQ(test::read_file(path), "x");
    }
    EXPECT_EQ(entries(dir.path()), 2u);
}

TEST(OutputTarget, CompressRefusesBeforeItReadsItsInput) {
    test::TempDir dir;
    {
        TckWriter w(dir.file("in.tck"), {}, true);
        for (int i = 0; i < 3000; ++i) w.write(std::vector<Vec3f>{{0, float(i), 0}, {0.1f, float(i), 0}});
        w.finish();
    }
    test::write_file(dir.file("exists.fft"), "x");
    int progress_calls = 0;
    CompressOptions o;
    o.progress = [&](const char*, double) { ++progress_calls; };
    EXPECT_EQ(error_of([&] { compress_file(dir.file("in.tck"), dir.file("exists.fft"), o); }), Errc::exists);
    o.overwrite = true;
    EXPECT_EQ(error_of([&] { compress_file(dir.file("in.tck"), dir.file("in.tck"), o); }), Errc::invalid_argument);
    EXPECT_EQ(progress_calls, 0);  // refused before the first pass, not after it
    compress_file(dir.file("in.tck"), dir.file("exists.fft"), o);
    EXPECT_GT(progress_calls, 0);
}

TEST(OutputTarget, DevStdoutIsWrittenThroughOrRefusedAsWhatItIs) {
    test::TempDir dir;
    test::write_three_fiber_tck(dir.file("in.tck"));
    ASSERT_EQ(test::run_cli("compress -q " + dir.file("in.tck") + " -o " + dir.file("in.fft")).status, 0);
    // stdout a pipe (popen): /dev/stdout -> /proc/self/fd/1 -> pipe:[N], a FIFO.
    const auto piped = test::run_cli("decompress -q " + dir.file("in.fft") + " -o /dev/stdout");
    EXPECT_EQ(piped.status, 2) << piped.output;
    EXPECT_NE(piped.output.find("FIFO"), std::string::npos) << piped.output;
    // stdout /dev/null (a character device through two links): written through.
    const auto r = test::run_command(std::string(FIBLET_CLI) + " decompress -q " + dir.file("in.fft") +
                                     " -o /dev/stdout >/dev/null 2>" + dir.file("err.txt"));
    EXPECT_EQ(r.status, 0) << test::read_file(dir.file("err.txt"));
    EXPECT_TRUE(is_char_device("/dev/null"));
}
