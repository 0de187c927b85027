// Internal: where each task's output ends, published in task order, for
// one parallel_for that writes variable-sized outputs one after the other
// (no join to learn the sizes first). A task publishes its size once known
// and gets where its output starts: it waits for the task before it, which
// the pool handed out earlier (so it runs or is done). A task that fails
// publishes kFailed, and those after it stop (parallel_parts).
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <limits>
#include <thread>
#include <vector>

#include "fiblet/parallel.hpp"

namespace fiblet::detail {

class OrderedEnds {
public:
    static constexpr std::uint64_t kPending = std::numeric_limits<std::uint64_t>::max(), kFailed = kPending - 1;

    explicit OrderedEnds(std::size_t tasks) : ends_(tasks) {
        for (auto& e : ends_) e.store(kPending, std::memory_order_relaxed);
    }

    // Task t's start (kFailed when a task before it failed); its end
    // becomes that + size.
    std::uint64_t publish(std::size_t t, std::uint64_t size) {
        std::uint64_t start = 0;
        if (t > 0)
            while ((start = ends_[t - 1].load(std::memory_order_acquire)) == kPending) std::this_thread::yield();
        ends_[t].store(start == kFailed ? kFailed : start + size, std::memory_order_release);
        return start;
    }

    // Publishes kFailed for task t unless it published (call on every exit).
    void fail_unless_published(std::size_t t) {
        if (ends_[t].load(std::memory_order_relaxed) == kPending) ends_[t].store(kFailed, std::memory_order_release);
    }

    std::size_t size() const { return ends_.size(); }

    // After the parallel_for: where the last task's output ends.
    std::uint64_t end() const { return ends_.empty() ? 0 : ends_.back().load(std::memory_order_acquire); }

    // Publishes kFailed on destruction unless the task published.
    struct Guard {
        OrderedEnds& ends;
        std::size_t task;
        ~Guard() { ends.fail_unless_published(task); }
    };

private:
    std::vector<std::atomic<std::uint64_t>> ends_;
};

// task(p) for every task of `ends` on `threads` threads, each task's
// publish guarded; the error reported is the first failed task's, whichever
// thread failed first (a damaged block fails its part's structure check
// and its group's checksum, which the next part may hash too): the tasks
// before a failed one run, those after it stop, and every thread count
// reports the same error.
template <class Task>
void parallel_parts(OrderedEnds& ends, unsigned threads, Task&& task) {
    const std::size_t parts = ends.size();
    std::vector<std::exception_ptr> failures(parts);
    std::atomic<std::size_t> first_failed{parts};
    parallel_for(parts, threads, [&](std::size_t p) {
        const OrderedEnds::Guard guard{ends, p};
        if (p > first_failed.load()) return;
        try {
            task(p);
        } catch (...) {
            failures[p] = std::current_exception();
            for (std::size_t f = first_failed.load(); p < f && !first_failed.compare_exchange_weak(f, p);) {
            }
        }
    });
    if (const std::size_t f = first_failed.load(); f < parts) std::rethrow_exception(failures[f]);
}

}  // namespace fiblet::detail
