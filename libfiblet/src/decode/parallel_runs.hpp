// Internal: run(n, work) calls work(0) .. work(n - 1) on n threads (the
// caller's thread runs work(0)) and rethrows the first exception once all
// are done. Threads are started per call: decoding hands them whole chunks
// (milliseconds of work), so starting them costs well under 1 %.
#pragma once

#include <exception>
#include <thread>
#include <vector>

namespace fiblet::detail {

template <class Work>
void parallel_runs(unsigned n, Work&& work) {
    if (n <= 1) {
        work(0u);
        return;
    }
    std::vector<std::exception_ptr> failure(n);
    std::vector<std::thread> pool;
    pool.reserve(n - 1);
    auto guarded = [&](unsigned t) {
        try {
            work(t);
        } catch (...) {
            failure[t] = std::current_exception();
        }
    };
    for (unsigned t = 1; t < n; ++t) pool.emplace_back(guarded, t);
    guarded(0);
    for (auto& th : pool) th.join();
    for (auto& f : failure)
        if (f) std::rethrow_exception(f);
}

}  // namespace fiblet::detail
