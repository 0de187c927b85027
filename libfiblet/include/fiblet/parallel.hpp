// The library's one pool of worker threads, shared by compression,
// decoding, selection and the Python module: started on first use, kept for
// the life of the process (grown when a caller asks for more threads than it
// has), so no call or batch pays for starting threads.
//
// Work is handed out task by task from a shared counter (dynamic chunking):
// a thread the OS schedules late, or one that gets slower tasks, takes fewer
// of them, and the caller always takes part, so a job finishes even when
// every worker is busy elsewhere (nested jobs cannot deadlock).
#pragma once

#include <cstddef>
#include <functional>
#include <memory>

namespace fiblet {

// Runs task(0) .. task(n - 1), each exactly once, on up to `threads` threads
// (the caller's included; 0 = all cores), and returns when all are done. The
// first exception a task throws is rethrown here once the others have
// finished (tasks not yet started are then skipped). Which thread runs which
// task varies from run to run: a task must write only its own outputs.
void parallel_for(std::size_t n, unsigned threads, const std::function<void(std::size_t)>& task);

// A parallel_for started in the background: the pool's workers begin on it
// at once; wait() (or the destructor) has the caller take the tasks left and
// waits for the rest. Lets a caller overlap its own serial work (reading the
// next batch) with the tasks.
class ParallelJob {
public:
    ParallelJob() = default;
    ParallelJob(std::size_t n, unsigned threads, std::function<void(std::size_t)> task);
    ParallelJob(ParallelJob&&) noexcept;
    ParallelJob& operator=(ParallelJob&&) noexcept;
    ~ParallelJob();
    // Takes part until every task has run; rethrows a task's exception.
    // With `meanwhile` (a job started after this one): once this job's
    // tasks are all claimed, the caller runs meanwhile's tasks, one at a
    // time, until this job's last task is done, instead of idling while
    // another thread finishes it (a pipeline's next batch).
    void wait(ParallelJob* meanwhile = nullptr);
    struct State;

private:
    std::shared_ptr<State> state_;
};

}  // namespace fiblet
