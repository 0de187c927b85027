// The persistent worker pool behind fiblet::parallel_for (fiblet/parallel.hpp).
//
// Jobs wait in a queue; an idle worker joins the oldest job that still has
// unclaimed tasks and room for another thread (a job asked for `threads`
// runs on at most threads - 1 workers plus its caller), then claims tasks
// one at a time from the job's atomic counter. The caller claims tasks too,
// in wait(), so a job never depends on a worker being free.
#include <pthread.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "core/thread_count.hpp"
#include "fiblet/parallel.hpp"

namespace fiblet {

struct ParallelJob::State {
    std::function<void(std::size_t)> task;
    std::size_t n = 0;
    unsigned max_workers = 0;  // besides the caller
    unsigned workers = 0;      // joined so far (under the pool's mutex)
    std::atomic<std::size_t> next{0}, done{0};
    std::atomic<bool> failed{false};
    std::exception_ptr error;  // the first failure (under mutex)
    std::mutex mutex;
    std::condition_variable finished;

    // Claims and runs one task; false when none was left.
    bool take_one() {
        const std::size_t i = next.fetch_add(1, std::memory_order_relaxed);
        if (i >= n) return false;
        if (!failed.load(std::memory_order_relaxed)) {
            try {
                task(i);
            } catch (...) {
                const std::lock_guard<std::mutex> lock(mutex);
                if (!error) error = std::current_exception();
                failed = true;
            }
        }
        if (done.fetch_add(1, std::memory_order_acq_rel) + 1 == n) {
            const std::lock_guard<std::mutex> lock(mutex);
            finished.notify_all();
        }
        return true;
    }
    // Claims and runs tasks until none is left.
    void take_part() {
        while (take_one()) {
        }
    }
    bool all_done() const { return done.load(std::memory_order_acquire) >= n; }
    bool open() const { return next.load(std::memory_order_relaxed) < n && workers < max_workers; }
};

namespace {

class WorkerPool {
public:
    static WorkerPool& instance() {
        static const bool registered = [] {
            // A forked child has none of the parent's threads: it starts a pool of its own.
            ::pthread_atfork(nullptr, nullptr, [] { current() = new WorkerPool; });
            return true;
        }();
        (void)registered;
        return *current();
    }

    void submit(const std::shared_ptr<ParallelJob::State>& job) {
        if (job->max_workers == 0) return;
        std::unique_lock<std::mutex> lock(mutex_);
        // Workers for the threads asked for (the pool never shrinks; left
        // running at exit, as the process ends).
        for (; size_ < job->max_workers; ++size_) std::thread([this] { work(); }).detach();
        queue_.push_back(job);
        lock.unlock();
        wake_.notify_all();
    }

    // The job is done with: out of the queue if a worker has not dropped it yet.
    void retire(const std::shared_ptr<ParallelJob::State>& job) {
        const std::lock_guard<std::mutex> lock(mutex_);
        queue_.erase(std::remove(queue_.begin(), queue_.end(), job), queue_.end());
    }

private:
    static WorkerPool*& current() {
        static WorkerPool* pool = new WorkerPool;  // never destroyed: workers may outlive static destructors
        return pool;
    }

    void work() {
        for (;;) {
            std::shared_ptr<ParallelJob::State> job;
            {
                std::unique_lock<std::mutex> lock(mutex_);
                wake_.wait(lock, [&] {
                    // Drop the jobs whose tasks are all claimed.
                    while (!queue_.empty() && queue_.front()->next.load(std::memory_order_relaxed) >= queue_.front()->n)
                        queue_.pop_front();
                    for (const auto& j : queue_)
                        if (j->open()) return true;
                    return false;
                });
                for (const auto& j : queue_)
                    if (j->open()) {
                        job = j;
                        break;
                    }
                ++job->workers;
            }
            job->take_part();
        }
    }

    std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<std::shared_ptr<ParallelJob::State>> queue_;
    unsigned size_ = 0;  // workers started
};

}  // namespace

ParallelJob::ParallelJob(std::size_t n, unsigned threads, std::function<void(std::size_t)> task)
    : state_(std::make_shared<State>()) {
    threads = detail::resolve_threads(threads);
    state_->task = std::move(task);
    state_->n = n;
    state_->max_workers = unsigned(std::min<std::size_t>(threads, n == 0 ? 1 : n) - 1);
    WorkerPool::instance().submit(state_);
}

ParallelJob::ParallelJob(ParallelJob&&) noexcept = default;

ParallelJob& ParallelJob::operator=(ParallelJob&& o) noexcept {
    if (this != &o) {
        try {
            if (state_) wait();
        } catch (...) {
        }
        state_ = std::move(o.state_);
    }
    return *this;
}

ParallelJob::~ParallelJob() {
    try {
        if (state_) wait();
    } catch (...) {  // the owner is unwinding already, or never asked
    }
}

void ParallelJob::wait(ParallelJob* meanwhile) {
    const std::shared_ptr<State> s = std::move(state_);
    if (!s) return;
    s->take_part();
    if (meanwhile && meanwhile->state_)
        while (!s->all_done() && meanwhile->state_->take_one()) {
        }
    {
        std::unique_lock<std::mutex> lock(s->mutex);
        s->finished.wait(lock, [&] { return s->all_done(); });
    }
    if (s->max_workers) WorkerPool::instance().retire(s);
    if (s->error) std::rethrow_exception(s->error);
}

void parallel_for(std::size_t n, unsigned threads, const std::function<void(std::size_t)>& task) {
    if (n == 0) return;
    if (n == 1 || detail::resolve_threads(threads) == 1) {
        for (std::size_t i = 0; i < n; ++i) task(i);
        return;
    }
    ParallelJob(n, threads, std::cref(task)).wait();
}

}  // namespace fiblet
