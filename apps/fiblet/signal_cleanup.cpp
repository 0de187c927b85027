// Fatal signals in the CLI: remove the pending temporary outputs, say which
// signal stopped the command (a silent death after `ulimit -f` leaves the
// user guessing), exit with 128 + signal, the shell convention. The policy
// is the CLI's; the library only keeps its pending outputs removable
// (fiblet::remove_pending_outputs, fiblet::fatal_signals).
#include "signal_cleanup.hpp"

#include <signal.h>
#include <unistd.h>

#include <cstring>

#include "fiblet/output_file.hpp"

namespace fiblet::cli {
namespace {

const char* signal_text(int sig) {
    switch (sig) {
        case SIGINT: return "SIGINT (interrupted)";
        case SIGTERM: return "SIGTERM (terminated)";
        case SIGHUP: return "SIGHUP (hang-up)";
        case SIGQUIT: return "SIGQUIT (quit)";
        case SIGPIPE: return "SIGPIPE (the reader of a pipe went away)";
        case SIGXFSZ: return "SIGXFSZ (file size limit reached, see ulimit -f)";
        case SIGXCPU: return "SIGXCPU (CPU time limit reached, see ulimit -t)";
        case SIGUSR1: return "SIGUSR1";
        case SIGUSR2: return "SIGUSR2";
        case SIGALRM: return "SIGALRM";
        case SIGVTALRM: return "SIGVTALRM";
        case SIGPROF: return "SIGPROF";
    }
    return "a signal";
}

// write(2) only: the handler may run in the middle of malloc or stdio.
void say(const char* s) {
    for (std::size_t left = std::strlen(s); left > 0;) {
        const ssize_t n = ::write(STDERR_FILENO, s, left);
        if (n <= 0) return;
        s += n, left -= std::size_t(n);
    }
}

void handle_signal(int sig) {
    remove_pending_outputs();
    // SIGINT is the user's own Ctrl-C: the shell already shows it; SIGPIPE
    // ends `fiblet ... | head` as it ends any Unix filter, silently.
    if (sig != SIGINT && sig != SIGPIPE) {
        say("fiblet: stopped by ");
        say(signal_text(sig));
        say("; unfinished outputs removed\n");
    }
    ::_exit(128 + sig);
}

}  // namespace

void install_signal_cleanup() {
    struct sigaction sa {};
    sa.sa_handler = handle_signal;
    sigemptyset(&sa.sa_mask);
    for (int sig : fatal_signals()) sigaddset(&sa.sa_mask, sig);  // one handler at a time
    for (int sig : fatal_signals()) {
        struct sigaction old {};
        // A signal ignored by whoever started us (nohup: SIGHUP) stays ignored.
        if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
        ::sigaction(sig, &sa, nullptr);
    }
}

}  // namespace fiblet::cli
