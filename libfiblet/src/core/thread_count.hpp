// Internal: the one place a caller's thread count is checked and resolved.
// A count is a request for std::thread objects (and per-thread buffers): an
// absurd one (-j 4294967295) must be a clear usage error, not a failed
// allocation or thread creation deep inside a codec.
#pragma once

#include <algorithm>
#include <string>
#include <thread>

#include "fiblet/error.hpp"

namespace fiblet::detail {

inline constexpr unsigned kMaxThreads = 1024;

// 0 means all cores. Throws Error{invalid_argument} above kMaxThreads.
inline unsigned resolve_threads(unsigned requested) {
    if (requested > kMaxThreads)
        throw Error(Errc::invalid_argument, "thread count " + std::to_string(requested) + " is out of range: at most " +
                                                std::to_string(kMaxThreads) + " (0 = all cores)");
    return requested ? requested : std::max(1u, std::thread::hardware_concurrency());
}

}  // namespace fiblet::detail
