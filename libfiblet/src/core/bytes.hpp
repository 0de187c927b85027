// Internal: little-endian (de)serialization of fixed-size fields.
#pragma once

#include <cstdint>
#include <cstring>
#include <type_traits>
#include <vector>

namespace fiblet::detail {

template <class T>
void put_le(std::vector<std::uint8_t>& out, T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const std::size_t at = out.size();
    out.resize(at + sizeof(T));
    std::memcpy(out.data() + at, &value, sizeof(T));  // hosts are little-endian (checked in CMake)
}

template <class T>
T get_le(const std::uint8_t* p) {
    T value;
    std::memcpy(&value, p, sizeof(T));
    return value;
}

}  // namespace fiblet::detail
