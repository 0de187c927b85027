// Internal: where each task's output ends, published in task order, for
// one parallel_for that writes variable-sized outputs one after the other
// (no join to learn the sizes first). A task publishes its size once known
// and gets where its output starts: it waits for the task before it, which
// the pool handed out earlier (so it runs or is done). A task that fails
// publishes kFailed, and those after it stop.
#pragma once

#include <atomic>
#include <cstdint>
#include <limits>
#include <thread>
#include <vector>

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

}  // namespace fiblet::detail
