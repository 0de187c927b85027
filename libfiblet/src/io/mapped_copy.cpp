#include "io/mapped_copy.hpp"

#include <setjmp.h>
#include <signal.h>

#include <atomic>
#include <cstring>
#include <mutex>

namespace fiblet::detail {

namespace {

// Where this thread's guarded read returns to on SIGBUS (null: none).
thread_local sigjmp_buf* volatile t_read_guard = nullptr;
struct sigaction g_previous_sigbus {};

void on_sigbus(int sig, siginfo_t* info, void* context) {
    if (sigjmp_buf* guard = t_read_guard) siglongjmp(*guard, 1);
    // Not a guarded read: the handler from before. SIG_DFL (or SIG_IGN, which
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

// Runs read(arg) under the guard: false when it faulted with SIGBUS.
// `read` must be a plain read of the mapping (see the header).
bool read_guarded(void (*read)(void*), void* arg) {
    static std::once_flag installed;
    std::call_once(installed, install_sigbus_handler);
    sigjmp_buf guard;
    if (sigsetjmp(guard, 0) != 0) {
        t_read_guard = nullptr;
        return false;
    }
    t_read_guard = &guard;
    std::atomic_signal_fence(std::memory_order_seq_cst);
    read(arg);
    std::atomic_signal_fence(std::memory_order_seq_cst);
    t_read_guard = nullptr;
    return true;
}

}  // namespace

bool copy_from_mapping(std::span<const MappedCopy> copies) {
    return read_guarded(
        [](void* arg) {
            const auto& c = *static_cast<const std::span<const MappedCopy>*>(arg);
            for (std::size_t i = 0; i < c.size(); ++i) {
                if (i + 8 < c.size()) __builtin_prefetch(c[i + 8].from);  // scattered blocks: fetch ahead
                std::memcpy(c[i].to, c[i].from, c[i].bytes);
            }
        },
        &copies);
}

bool hash_from_mapping(const void* from, std::size_t bytes, Xxh64Stream& hash) {
    struct Args {
        const void* from;
        std::size_t bytes;
        Xxh64Stream& hash;
    } args{from, bytes, hash};
    return read_guarded([](void* arg) {
        const Args& a = *static_cast<const Args*>(arg);
        a.hash.update(a.from, a.bytes);
    }, &args);
}

}  // namespace fiblet::detail
