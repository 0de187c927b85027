// Handing a std::vector's buffer to numpy without copying it: the vector is
// moved to the heap and owned by a capsule that numpy keeps as the array's
// base, so the buffer lives exactly as long as the last array viewing it.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <utility>
#include <vector>

namespace fiblet::python {

// An array of `shape` over the vector's elements, reinterpreted as `View`
// (same size: e.g. uint64 offsets exposed as numpy's int64, the index type
// numpy and nibabel compute with).
template <typename View, typename T>
pybind11::array_t<View> to_numpy(std::vector<T>&& values, std::vector<pybind11::ssize_t> shape) {
    static_assert(sizeof(View) == sizeof(T));
    auto* owned = new std::vector<T>(std::move(values));
    pybind11::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
    return pybind11::array_t<View>(std::move(shape), reinterpret_cast<const View*>(owned->data()), owner);
}

}  // namespace fiblet::python
