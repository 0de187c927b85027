// fiblet_peak_rss PROGRAM ARGS...: runs PROGRAM with its output discarded
// and prints "STATUS PEAK_KB": its exit code (128 + n when killed by signal
// n) and its peak resident set in kB. The tests' memory bounds measure
// fiblet through it: a child forked straight from the test process carries
// that process's resident memory in its own peak (fork copies the page
// tables, and exec keeps the high-water mark), while this small process's
// child starts from almost nothing, whatever the tests ran before.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: fiblet_peak_rss PROGRAM [ARGS...]\n");
        return 2;
    }
    const pid_t pid = ::fork();
    if (pid < 0) return 127;
    if (pid == 0) {
        const int null = ::open("/dev/null", O_WRONLY);
        ::dup2(null, 1), ::dup2(null, 2);
        ::execv(argv[1], argv + 1);
        ::_exit(127);
    }
    int status = 0;
    rusage usage{};
    if (::wait4(pid, &status, 0, &usage) != pid) return 127;
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1;
    std::printf("%d %ld\n", code, usage.ru_maxrss);
    return 0;
}
