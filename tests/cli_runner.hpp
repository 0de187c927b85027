// Running commands, and the fiblet CLI (FIBLET_CLI), from the tests.
#pragma once

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

namespace fiblet::test {

struct CommandResult {
    int status = -1;     // exit code; 128 + n when killed by signal n; -1 when it could not start
    std::string output;  // what it wrote to stdout
};

// Runs `cmd` through the shell (add 2>&1 to capture stderr too).
inline CommandResult run_command(const std::string& cmd) {
    CommandResult r;
    FILE* p = ::popen(cmd.c_str(), "r");
    if (!p) return r;
    char buf[4096];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) r.output.append(buf, n);
    const int st = ::pclose(p);
    r.status = WIFEXITED(st) ? WEXITSTATUS(st) : WIFSIGNALED(st) ? 128 + WTERMSIG(st) : -1;
    return r;
}

// `fiblet ARGS`, stdout and stderr captured; `env` goes before it (e.g. "env -u DISPLAY").
inline CommandResult run_cli(const std::string& args, const std::string& env = "") {
    return run_command(env + " " + FIBLET_CLI + " " + args + " 2>&1");
}

// Starts `fiblet args...` with its output discarded; returns its pid (the
// caller waits for it). Its peak RSS (wait4) would include what the test
// process had resident when it forked: memory bounds use run_cli_peak.
inline pid_t spawn_cli(const std::vector<std::string>& args) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        const int null = ::open("/dev/null", O_WRONLY);
        ::dup2(null, 1), ::dup2(null, 2);
        std::vector<char*> argv{const_cast<char*>(FIBLET_CLI)};
        for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        ::execv(FIBLET_CLI, argv.data());
        ::_exit(127);
    }
    return pid;
}

// `fiblet args...` with its output discarded: its exit status (as
// CommandResult's) and its peak RSS in MB, measured by fiblet_peak_rss
// (tests/tools/peak_rss.cpp), whatever this process holds.
struct PeakRun {
    int status = -1;
    double peak_mb = 0;
};
inline PeakRun run_cli_peak(const std::vector<std::string>& args) {
    auto quoted = [](const std::string& s) {
        std::string q = "'";
        for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
        return q + "'";
    };
    std::string cmd = quoted(FIBLET_PEAK_RSS) + " " + quoted(FIBLET_CLI);
    for (const std::string& a : args) cmd += " " + quoted(a);
    const CommandResult r = run_command(cmd);
    PeakRun out;
    long kb = 0;
    if (r.status != 0 || std::sscanf(r.output.c_str(), "%d %ld", &out.status, &kb) != 2) return PeakRun{};
    out.peak_mb = double(kb) / 1024.0;
    return out;
}

}  // namespace fiblet::test
