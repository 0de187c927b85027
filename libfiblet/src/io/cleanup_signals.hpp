// Internal: the signals after which pending temporary outputs are removed
// (every signal whose default action ends the process and that can be
// caught), and a guard that holds them off while the registry of pending
// temporaries changes.
#pragma once

#include <pthread.h>
#include <signal.h>

namespace fiblet::detail {

// SIGINT, SIGTERM, SIGHUP: stop requests. SIGPIPE: a closed pipe on stdout.
// SIGXFSZ, SIGXCPU: `ulimit -f` / `ulimit -t` reached. The others end the
// process by default when someone sends them (kill -USR1 ...).
inline constexpr int kCleanupSignals[] = {SIGINT,  SIGTERM, SIGHUP,    SIGQUIT,   SIGPIPE, SIGXFSZ,
                                          SIGXCPU, SIGUSR1, SIGUSR2,   SIGALRM,   SIGVTALRM, SIGPROF};

// Blocks the cleanup signals in this thread for its lifetime.
class SignalBlock {
public:
    SignalBlock() {
        sigset_t set;
        sigemptyset(&set);
        for (int sig : kCleanupSignals) sigaddset(&set, sig);
        ::pthread_sigmask(SIG_BLOCK, &set, &old_);
    }
    ~SignalBlock() { ::pthread_sigmask(SIG_SETMASK, &old_, nullptr); }
    SignalBlock(const SignalBlock&) = delete;
    SignalBlock& operator=(const SignalBlock&) = delete;

private:
    sigset_t old_;
};

}  // namespace fiblet::detail
