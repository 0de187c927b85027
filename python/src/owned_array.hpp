// Handing a buffer to numpy without copying it: the buffer's owner (a
// std::vector, or a PopulatedBuffer) is moved to the heap and held by a
// capsule that numpy keeps as the array's base, so the memory lives exactly
// as long as the last array viewing it.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <utility>
#include <vector>

#include "populated_buffer.hpp"

namespace fiblet::python {

template <typename Owner>
pybind11::capsule owning_capsule(Owner*& owned, Owner&& owner) {
    owned = new Owner(std::move(owner));
    return pybind11::capsule(owned, [](void* p) { delete static_cast<Owner*>(p); });
}

// An array of `shape` over the vector's elements, reinterpreted as `View`
// (same size: e.g. uint64 offsets exposed as numpy's int64, the index type
// numpy and nibabel compute with).
template <typename View, typename T>
pybind11::array_t<View> to_numpy(std::vector<T>&& values, std::vector<pybind11::ssize_t> shape) {
    static_assert(sizeof(View) == sizeof(T));
    std::vector<T>* owned = nullptr;
    pybind11::capsule owner = owning_capsule(owned, std::move(values));
    return pybind11::array_t<View>(std::move(shape), reinterpret_cast<const View*>(owned->data()), owner);
}

template <typename View>
pybind11::array_t<View> to_numpy(PopulatedBuffer&& buffer, std::vector<pybind11::ssize_t> shape) {
    PopulatedBuffer* owned = nullptr;
    pybind11::capsule owner = owning_capsule(owned, std::move(buffer));
    return pybind11::array_t<View>(std::move(shape), owned->as<const View>(), owner);
}

}  // namespace fiblet::python
