// Internal: an allocator whose vector::resize leaves new elements of a
// trivial type uninitialized, for buffers that are written right after they
// grow (zero-filling them first cost as much as a tenth of a small query).
#pragma once

#include <memory>
#include <new>
#include <utility>
#include <vector>

namespace fiblet::detail {

template <class T, class Base = std::allocator<T>>
struct DefaultInitAllocator : Base {
    using Base::Base;
    template <class U>
    struct rebind {
        using other = DefaultInitAllocator<U, typename std::allocator_traits<Base>::template rebind_alloc<U>>;
    };
    template <class U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        ::new (static_cast<void*>(p)) U;  // default-, not value-initialized
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        std::allocator_traits<Base>::construct(static_cast<Base&>(*this), p, std::forward<Args>(args)...);
    }
};

// A vector whose growth is not zero-filled.
template <class T>
using UninitializedVector = std::vector<T, DefaultInitAllocator<T>>;

}  // namespace fiblet::detail
