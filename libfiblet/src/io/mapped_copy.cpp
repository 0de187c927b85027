#include "io/mapped_copy.hpp"

#include <setjmp.h>
#include <signal.h>

#include <atomic>
#include <cstring>
#include <mutex>

namespace fiblet::detail {

namespace {

// Where this thread's copy in progress returns to on SIGBUS (null: none).
thread_local sigjmp_buf* volatile t_copy_guard = nullptr;
struct sigaction g_previous_sigbus {};

void on_sigbus(int sig, siginfo_t* info, void* context) {
    if (sigjmp_buf* guard = t_copy_guard) siglongjmp(*guard, 1);
    // Not a guarded copy: the handler from before. SIG_DFL (or SIG_IGN, which
    // the kernel overrides for a fault) is restored and the faulting access,
    // repeated on return, ends the process as it would have without us.
    if (g_previous_sigbus.sa_flags & SA_SIGINFO) {
        g_previous_sigbus.sa_sigaction(sig, info, context);
    } else if (g_previous_sigbus.sa_handler == SIG_DFL || g_previous_sigbus.sa_handler == SIG_IGN) {
        ::sigaction(SIGBUS, &g_previous_sigbus, nullptr);
    } else {
        g_previous_sigbus.sa_handler(sig);
    }
}

void install_sigbus_handler() {
    struct sigaction a {};
    a.sa_sigaction = on_sigbus;
    // SA_NODEFER: SIGBUS stays unblocked after the jump, so sigsetjmp need
    // not save the signal mask (a system call per copy).
    a.sa_flags = SA_SIGINFO | SA_NODEFER;
    sigemptyset(&a.sa_mask);
    ::sigaction(SIGBUS, &a, &g_previous_sigbus);
}

}  // namespace

bool copy_from_mapping(std::span<const MappedCopy> copies) {
    static std::once_flag installed;
    std::call_once(installed, install_sigbus_handler);
    sigjmp_buf guard;
    if (sigsetjmp(guard, 0) != 0) {
        t_copy_guard = nullptr;
        return false;
    }
    t_copy_guard = &guard;
    std::atomic_signal_fence(std::memory_order_seq_cst);
    const std::size_t n = copies.size();
    for (std::size_t i = 0; i < n; ++i) {
        if (i + 8 < n) __builtin_prefetch(copies[i + 8].from);  // scattered blocks: fetch ahead
        std::memcpy(copies[i].to, copies[i].from, copies[i].bytes);
    }
    std::atomic_signal_fence(std::memory_order_seq_cst);
    t_copy_guard = nullptr;
    return true;
}

}  // namespace fiblet::detail
