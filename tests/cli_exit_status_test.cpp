// Fatal signals and stream errors in the CLI (issue 12, class 7): a signal
// removes the temporary output and says what stopped the command; a report
// that cannot reach stdout is a failure; --json is valid UTF-8 whatever bytes
// the files hold.
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <string>

#include "cli_runner.hpp"
#include "fiblet/tck.hpp"
#include "test_util.hpp"

using namespace fiblet;
namespace fs = std::filesystem;

namespace {

// RFC 3629 well-formedness, written independently of the CLI's encoder.
bool valid_utf8(const std::string& s) {
    for (std::size_t i = 0; i < s.size();) {
        const unsigned char c = static_cast<unsigned char>(s[i]);
        std::size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
        if (n == 0 || i + n > s.size()) return false;
        std::uint32_t cp = n == 1 ? c : n == 2 ? c & 0x1F : n == 3 ? c & 0x0F : c & 0x07;
        for (std::size_t k = 1; k < n; ++k) {
            const unsigned char d = static_cast<unsigned char>(s[i + k]);
            if ((d & 0xC0) != 0x80) return false;
            cp = cp << 6 | (d & 0x3F);
        }
        const std::uint32_t min[] = {0, 0, 0x80, 0x800, 0x10000};
        if (cp < min[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
        i += n;
    }
    return true;
}

std::size_t entries(const std::string& dir) {
    return std::size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

// A .tck of `fibers` straight fibers of 200 points (a few hundred kB).
void write_tck(const std::string& path, int fibers) {
    TckWriter w(path, {}, true);
    std::vector<Vec3f> f(200);
    for (int i = 0; i < fibers; ++i) {
        for (std::size_t k = 0; k < f.size(); ++k) f[k] = {0.1f * float(k), float(i % 50), 0.01f * float(k * i % 97)};
        w.write(f);
    }
    w.finish();
}

}  // namespace

TEST(CliExitStatus, FileSizeLimitRemovesTheTemporaryAndSaysSo) {
    test::TempDir dir;
    write_tck(dir.file("in.tck"), 2000);
    // ulimit -f counts 512-byte blocks: the output (hundreds of kB) exceeds 8.
    const auto r = test::run_command("cd " + dir.path() + " && ulimit -f 8 && " + FIBLET_CLI +
                                     " compress -q -j 1 in.tck -o out.fft 2>&1");
    EXPECT_EQ(r.status, 128 + SIGXFSZ) << r.output;
    EXPECT_NE(r.output.find("SIGXFSZ"), std::string::npos) << r.output;
    EXPECT_EQ(entries(dir.path()), 1u);  // in.tck only: no out.fft, no out.fft.tmp-*
}

TEST(CliExitStatus, AFullStdoutIsAnIoError) {
    test::TempDir dir;
    test::write_three_fiber_tck(dir.file("in.tck"));
    ASSERT_EQ(test::run_cli("compress -q " + dir.file("in.tck") + " -o " + dir.file("in.fft")).status, 0);
    for (const std::string& args : {"info --json " + dir.file("in.fft"), "verify --json " + dir.file("in.fft"),
                                    "info " + dir.file("in.tck")}) {
        const auto r = test::run_command(std::string(FIBLET_CLI) + " " + args + " 2>&1 >/dev/full");
        EXPECT_EQ(r.status, 3) << args << "\n" << r.output;
        EXPECT_NE(r.output.find("standard output"), std::string::npos) << r.output;
    }
}

TEST(CliExitStatus, JsonIsValidUtf8WhateverTheHeaderBytes) {
    test::TempDir dir;
    const std::string bad = "caf\xc3\xa9 \xff\xfe \xc3( \xed\xa0\x80 \xf4\x90\x80\x80 end\x01";
    {
        TckWriter w(dir.file("in.tck"), {{"comment", bad}, {"valid", "\xe2\x82\xac"}}, true);
        w.write(std::vector<Vec3f>{{0, 0, 0}, {0.1f, 0, 0}, {0.2f, 0, 0}});
        w.finish();
    }
    ASSERT_EQ(test::run_cli("compress -q " + dir.file("in.tck") + " -o " + dir.file("in.fft")).status, 0);
    for (const std::string& file : {dir.file("in.tck"), dir.file("in.fft")}) {
        const auto r = test::run_command(std::string(FIBLET_CLI) + " info --json " + file);
        ASSERT_EQ(r.status, 0) << r.output;
        EXPECT_TRUE(valid_utf8(r.output)) << r.output;
        // Each invalid byte becomes U+FFFD (written as UTF-8, as nlohmann::json does).
        EXPECT_NE(r.output.find("caf\xc3\xa9 \xef\xbf\xbd\xef\xbf\xbd \xef\xbf\xbd("), std::string::npos) << r.output;
        EXPECT_NE(r.output.find("\xe2\x82\xac"), std::string::npos) << r.output;  // valid UTF-8 is kept
        EXPECT_NE(r.output.find("end\\u0001"), std::string::npos) << r.output;
    }
}

class FatalSignal : public ::testing::TestWithParam<int> {};

// Signalled as soon as the temporary appears: the handler must remove it.
// (Not SIGINT or SIGQUIT here: sh starts background jobs with them ignored,
// and fiblet keeps ignored signals ignored; atomic_output_test sends SIGINT.)
TEST_P(FatalSignal, LeavesNoTemporaryAndSaysWhichSignal) {  // SIGPIPE: says nothing
    const int sig = GetParam();
    test::TempDir dir;
    write_tck(dir.file("in.tck"), 10000);
    const std::string cmd = std::string("cd ") + dir.path() + " && (" + FIBLET_CLI +
                            " compress -q -j 1 in.tck -o out.fft 2>err.txt & pid=$!; " +
                            "for i in $(seq 3000); do ls | grep -q tmp- && break; sleep 0.01; done; kill -" +
                            std::to_string(sig) +
                            " $pid; wait $pid; echo $?)";
    const auto r = test::run_command(cmd);
    EXPECT_EQ(std::stoi(r.output), 128 + sig) << r.output;
    const std::string err = test::read_file(dir.file("err.txt"));
    // Said for every signal but SIGPIPE (a reader of a pipe that went away, as in `| head`: silent).
    EXPECT_EQ(err.find("stopped by SIG") != std::string::npos, sig != SIGPIPE) << err;
    fs::remove(dir.file("err.txt"));
    EXPECT_EQ(entries(dir.path()), 1u);
}

INSTANTIATE_TEST_SUITE_P(Signals, FatalSignal, ::testing::Values(SIGUSR1, SIGHUP, SIGXFSZ, SIGPIPE),
                         [](const auto& info) { return std::string(sigabbrev_np(info.param)); });
