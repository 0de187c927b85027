// Internal: scratch arrays reused from fiber to fiber (thread_local or kept
// in a batch) are grown, never shrunk: each user writes the elements it
// reads, and resizing a vector back up after a shrink fills the new elements
// for nothing (measured: up to a tenth of the metrics, 0.6 % of the default
// compress for the encoder's batches).
#pragma once

#include <cstddef>
#include <vector>

namespace fiblet::detail {

// v holds at least n elements; returns its data.
template <class T, class A>
T* grow(std::vector<T, A>& v, std::size_t n) {
    if (v.size() < n) v.resize(n);
    return v.data();
}

}  // namespace fiblet::detail
