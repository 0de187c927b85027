// Atomic outputs: a temporary next to the destination, renamed only when
// complete; removed on error, on destruction without commit, and on
// SIGINT/SIGTERM (checked on the real CLI, signalled while it writes);
// existing outputs are never replaced without overwrite (-f/--force).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/inotify.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"
#include "fiblet/output_file.hpp"
#include "fiblet/tck.hpp"
#include "cli_runner.hpp"
#include "test_util.hpp"

using namespace fiblet;
namespace fs = std::filesystem;

namespace {

std::vector<std::string> listing(const std::string& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

Errc error_of(const std::function<void()>& fn) {
    try {
        fn();
    } catch (const Error& e) {
        return e.code();
    }
    return Errc::interrupted;  // marker: no error
}

// About `points` points in fibers of 1000, at a 0.1 mm step along helices.
void write_long_tractogram(const std::string& path, std::size_t points) {
    TckWriter w(path, {}, true);
    std::vector<Vec3f> f(1000);
    for (std::size_t n = 0, i = 0; n < points; n += f.size(), ++i) {
        for (std::size_t k = 0; k < f.size(); ++k) {
            const float t = 0.1f * float(k) / 5.0f;
            f[k] = {5.0f * std::cos(t + float(i)), 5.0f * std::sin(t + float(i)), 0.098f * float(k)};
        }
        w.write(f);
    }
    w.finish();
}

// Starts `fiblet args...`, sends `sig` as soon as a temporary output appears
// in `dir` (inotify), and returns the exit status (128 + signal by convention).
int signal_cli_while_writing(const std::vector<std::string>& args, const std::string& dir, int sig) {
    const int in = ::inotify_init1(IN_CLOEXEC);
    if (in < 0 || ::inotify_add_watch(in, dir.c_str(), IN_CREATE) < 0) return -1;
    const pid_t pid = test::spawn_cli(args);
    bool sent = false;
    alignas(inotify_event) char buf[4096];
    while (!sent) {
        pollfd p{in, POLLIN, 0};
        if (::poll(&p, 1, 20000) <= 0) break;  // no temporary within 20 s
        const ssize_t n = ::read(in, buf, sizeof buf);
        for (ssize_t off = 0; off < n && !sent;) {
            const auto* e = reinterpret_cast<const inotify_event*>(buf + off);
            if (e->len > 0 && std::string(e->name).find(".tmp-") != std::string::npos) {
                ::kill(pid, sig);
                sent = true;
            }
            off += ssize_t(sizeof(inotify_event) + e->len);
        }
    }
    ::close(in);
    int status = 0;
    ::waitpid(pid, &status, 0);
    if (!sent) return -2;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
}

}  // namespace

TEST(AtomicOutput, NothingAppearsUntilCommitAndNothingStaysWithoutIt) {
    test::TempDir dir;
    const std::string path = dir.file("out.bin");
    {
        AtomicOutputFile out(path, false);
        EXPECT_EQ(fs::path(out.temporary_path()).parent_path(), fs::path(path).parent_path());
        out.write("abc", 3);
        EXPECT_FALSE(fs::exists(path));
        EXPECT_TRUE(fs::exists(out.temporary_path()));
    }  // destroyed without commit: an error path
    EXPECT_TRUE(listing(dir.path()).empty());
    {
        AtomicOutputFile out(path, false);
        out.write("abc", 3);
        out.write_at("X", 1, 1);
        out.commit();
    }
    EXPECT_EQ(test::read_file(path), "aXc");
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"out.bin"});
}

TEST(AtomicOutput, NeverReplacesAnExistingFileWithoutOverwrite) {
    test::TempDir dir;
    const std::string path = dir.file("out.bin");
    test::write_file(path, "precious");
    EXPECT_EQ(error_of([&] { AtomicOutputFile out(path, false); }), Errc::exists);
    // An output that appears while we write (another process) is not replaced either.
    {
        AtomicOutputFile out(dir.file("late.bin"), false);
        out.write("mine", 4);
        test::write_file(dir.file("late.bin"), "theirs");
        EXPECT_EQ(error_of([&] { out.commit(); }), Errc::exists);
    }
    EXPECT_EQ(test::read_file(dir.file("late.bin")), "theirs");
    EXPECT_EQ(test::read_file(path), "precious");
    EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"late.bin", "out.bin"}));
    // With overwrite, the new content replaces the old in one step.
    {
        AtomicOutputFile out(path, true);
        out.write("new", 3);
        out.commit();
    }
    EXPECT_EQ(test::read_file(path), "new");
    // The writers refuse too.
    EXPECT_EQ(error_of([&] { TckWriter w(path, {}, false); }), Errc::exists);
    EXPECT_EQ(test::read_file(path), "new");
}

TEST(AtomicOutput, PendingTemporariesAreRemovedByTheSignalCleanup) {
    test::TempDir dir;
    AtomicOutputFile a(dir.file("a"), false), b(dir.file("b"), false);
    a.write("x", 1);
    ASSERT_EQ(listing(dir.path()).size(), 2u);
    remove_pending_outputs();  // what the SIGINT/SIGTERM handler runs
    EXPECT_TRUE(listing(dir.path()).empty());
}

TEST(AtomicOutput, CompressAndDecompressRefuseToOverwriteWithoutForce) {
    test::TempDir dir;
    write_long_tractogram(dir.file("in.tck"), 5000);
    compress_file(dir.file("in.tck"), dir.file("a.fft"), {});
    test::write_file(dir.file("b.tck"), "precious");
    CompressOptions o;
    EXPECT_EQ(error_of([&] { compress_file(dir.file("in.tck"), dir.file("b.tck"), o); }), Errc::exists);
    const std::string cli = FIBLET_CLI;
    EXPECT_EQ(WEXITSTATUS(std::system((cli + " decompress -q " + dir.file("a.fft") + " -o " + dir.file("b.tck") +
                                       " 2>/dev/null")
                                          .c_str())),
              5);
    EXPECT_EQ(test::read_file(dir.file("b.tck")), "precious");
    EXPECT_EQ(WEXITSTATUS(std::system(
                  (cli + " decompress -q -f " + dir.file("a.fft") + " -o " + dir.file("b.tck")).c_str())),
              0);
    EXPECT_NE(test::read_file(dir.file("b.tck")), "precious");
    EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"a.fft", "b.tck", "in.tck"}));
}

class SignalDuringWrite : public ::testing::TestWithParam<int> {};

TEST_P(SignalDuringWrite, LeavesNoTemporaryAndNoOutput) {
    const int sig = GetParam();
    test::TempDir dir;
    // Long enough that the signal lands while the temporary is being written:
    // 3 M points take ~100 ms to encode on one core at 30 M points/s (8-bit
    // codes: the default gives these smooth helices 16 bits, which the
    // encoder writes before the signal lands).
    write_long_tractogram(dir.file("in.tck"), 3'000'000);
    EXPECT_EQ(signal_cli_while_writing({"compress", "-q", "-j", "1", "--bits", "8", dir.file("in.tck"), "-o",
                                        dir.file("out.fft")},
                                       dir.path(), sig),
              128 + sig);
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"in.tck"});

    compress_file(dir.file("in.tck"), dir.file("in.fft"), {});
    EXPECT_EQ(signal_cli_while_writing({"decompress", "-q", dir.file("in.fft"), "-o", dir.file("out.tck")}, dir.path(),
                                       sig),
              128 + sig);
    EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"in.fft", "in.tck"}));
}

INSTANTIATE_TEST_SUITE_P(Signals, SignalDuringWrite, ::testing::Values(SIGINT, SIGTERM),
                         [](const auto& info) { return info.param == SIGINT ? "SIGINT" : "SIGTERM"; });

// Standard input and output go through spools in $TMPDIR: a signal while
// compress waits on standard input that does not end removes both, the
// input's partial copy and the output's spool.
class SignalDuringSpool : public ::testing::TestWithParam<int> {};

TEST_P(SignalDuringSpool, LeavesNoSpoolInTmpdir) {
    const int sig = GetParam();
    test::TempDir dir, tmp;
    // set -m: a background job of a shell without job control ignores SIGINT.
    // Standard input is a FIFO the script holds open: compress waits on it.
    test::write_file(dir.file("run.sh"),
                     "set -m\n"
                     "export TMPDIR=" + tmp.path() + "\n"
                     "mkfifo " + dir.file("in") + "\n" +
                     std::string(FIBLET_CLI) + " compress - -o - < " + dir.file("in") + " >/dev/null 2>&1 &\n"
                     "pid=$!\n"
                     "exec 3>" + dir.file("in") + "\n"
                     "printf 'mrtrix tracks\\n' >&3\n"
                     "for i in $(seq 600); do [ $(ls " + tmp.path() + " | wc -l) -ge 2 ] && break; sleep 0.05; done\n"
                     "ls " + tmp.path() + " | sed 's/stdio-.*[.]/stdio-*./' | sort\n"
                     "kill -" + std::to_string(sig) + " $pid\n"
                     "wait $pid\n"
                     "echo status $?\n"
                     "exec 3>&-\n"
                     "ls " + tmp.path() + "\n");
    const auto r = test::run_command("bash " + dir.file("run.sh"));
    // Both spools existed while compress waited, and none is left.
    EXPECT_EQ(r.output, "fiblet-stdio-*.fft\nfiblet-stdio-*.tck\nstatus " + std::to_string(128 + sig) + "\n");
}

INSTANTIATE_TEST_SUITE_P(Signals, SignalDuringSpool, ::testing::Values(SIGINT, SIGTERM, SIGHUP),
                         [](const auto& info) {
                             return info.param == SIGINT ? "SIGINT" : info.param == SIGTERM ? "SIGTERM" : "SIGHUP";
                         });
