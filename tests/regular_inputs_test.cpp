// Inputs that are not regular files — a FIFO under any name, a process
// substitution's pipe, a .mih whose file: names a FIFO — are refused at once
// as I/O errors (exit 3), never opened: open() of a FIFO blocks until a
// writer comes, and a format detector reading a pipe consumed the bytes its
// reader then missed. Each command runs under `timeout` so that a hang
// fails the test instead of stalling the suite.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <string>

#include "cli_runner.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/image.hpp"
#include "fiblet/streamline_io.hpp"
#include "fiblet/tractogram_format.hpp"
#include "test_util.hpp"

namespace fiblet {
namespace {

using test::TempDir;

constexpr int kTimedOut = 124;  // timeout(1)'s status

std::string fifo(const TempDir& dir, const std::string& name) {
    const std::string path = dir.file(name);
    EXPECT_EQ(::mkfifo(path.c_str(), 0600), 0);
    return path;
}

test::CommandResult cli_with_timeout(const std::string& args) {
    return test::run_command("timeout 20 " + std::string(FIBLET_CLI) + " " + args + " 2>&1");
}

TEST(RegularInputs, TheApiRefusesFifosWithoutOpeningThem) {
    TempDir dir;
    // Nothing writes to these FIFOs: a reader that opened one would block here for good.
    EXPECT_EQ(test::error_of([&] { open_streamline_source(fifo(dir, "a.tck")); }), Errc::io);
    EXPECT_EQ(test::error_of([&] { open_streamline_source(fifo(dir, "b.trk")); }), Errc::io);
    EXPECT_EQ(test::error_of([&] { FftFile f(fifo(dir, "c.fft")); }), Errc::io);
    EXPECT_EQ(test::error_of([&] { read_image(fifo(dir, "d.nii")); }), Errc::io);
    EXPECT_EQ(test::error_of([&] { read_image(fifo(dir, "e.mif")); }), Errc::io);
    EXPECT_EQ(detect_tractogram_format(fifo(dir, "f.trx")), TractogramFormat::unknown);
}

TEST(RegularInputs, CommandsOnFifosExitThreeAtOnce) {
    TempDir dir;
    for (const std::string name : {"x.tck", "x.trk", "x.trx", "x.fft", "x.bin"}) {
        SCOPED_TRACE(name);
        const std::string path = fifo(dir, name);
        const auto compress = cli_with_timeout("compress -q " + path + " -o " + dir.file("out.fft"));
        EXPECT_EQ(compress.status, 3) << compress.output;
        EXPECT_NE(compress.output.find("not a regular file (a pipe)"), std::string::npos) << compress.output;
        EXPECT_FALSE(std::filesystem::exists(dir.file("out.fft")));
        const auto info = cli_with_timeout("info " + path);
        EXPECT_EQ(info.status, 3) << info.output;
        std::filesystem::remove(path);
    }
}

TEST(RegularInputs, MasksAndMihDataThatAreFifosExitThree) {
    TempDir dir;
    const std::string tck = dir.file("t.tck"), fft = dir.file("t.fft");
    test::write_file(tck, "mrtrix tracks\ndatatype: Float32LE\nfile: . 64\nEND\n");
    {
        std::string data = test::read_file(tck);
        data.resize(64, '\0');
        const float pts[] = {0, 0, 0, 1, 0, 0, NAN, NAN, NAN, INFINITY, INFINITY, INFINITY};
        data.append(reinterpret_cast<const char*>(pts), sizeof pts);
        test::write_file(tck, data);
    }
    ASSERT_EQ(test::run_cli("compress -q " + tck + " -o " + fft).status, 0);
    const auto nii = cli_with_timeout("extract " + fft + " --include " + fifo(dir, "mask.nii") + " -o " + dir.file("o.tck"));
    EXPECT_EQ(nii.status, 3) << nii.output;
    // A .mih whose data file is a FIFO: the header reads, the data does not block.
    fifo(dir, "data.raw");
    test::write_file(dir.file("mask.mih"),
                     "mrtrix image\ndim: 2,2,2\nvox: 1,1,1\nlayout: +0,+1,+2\ndatatype: UInt8\n"
                     "transform: 1,0,0,0\ntransform: 0,1,0,0\ntransform: 0,0,1,0\nfile: data.raw 0\nEND\n");
    const auto mih = cli_with_timeout("extract " + fft + " --include " + dir.file("mask.mih") + " -o " + dir.file("o.tck"));
    EXPECT_EQ(mih.status, 3) << mih.output;
    EXPECT_NE(mih.output.find("data.raw: not a regular file (a pipe)"), std::string::npos) << mih.output;
}

// `compress <(cat x.tck)`: bash's process substitution is a pipe; the
// detector used to consume its first bytes and the reader then found no magic.
TEST(RegularInputs, ProcessSubstitutionIsNamedAPipe) {
    if (!test::shared_data_available()) GTEST_SKIP() << "no shared data";
    TempDir dir;
    const auto r = test::run_command("timeout 20 bash -c '" + std::string(FIBLET_CLI) + " compress -q <(cat " +
                                     test::shared_data("small-ifod1.tck") + ") -o " + dir.file("o.fft") + "' 2>&1");
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_NE(r.output.find("not a regular file (a pipe)"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("take - for standard input"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace fiblet
