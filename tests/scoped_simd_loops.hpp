// The library's hand-written SIMD loops (core/points_avx2.hpp) switched on
// or off on this thread for a scope: tests compare each level with the
// scalar loops. The AVX-512 loops run only where the AVX2 ones do.
#pragma once

#include "core/points_avx2.hpp"

namespace fiblet::test {

class ScopedSimdLoops {
public:
    explicit ScopedSimdLoops(bool avx2, bool avx512 = true)
        : avx2_(detail::avx2_loops_enabled()), avx512_(detail::avx512_loops_enabled()) {
        detail::avx2_loops_enabled() = avx2, detail::avx512_loops_enabled() = avx512;
    }
    ~ScopedSimdLoops() { detail::avx2_loops_enabled() = avx2_, detail::avx512_loops_enabled() = avx512_; }
    ScopedSimdLoops(const ScopedSimdLoops&) = delete;
    ScopedSimdLoops& operator=(const ScopedSimdLoops&) = delete;

private:
    bool avx2_, avx512_;
};

// f() with the loops switched so.
template <class F>
auto with_simd_loops(bool avx2, bool avx512, F&& f) {
    const ScopedSimdLoops loops(avx2, avx512);
    return f();
}

}  // namespace fiblet::test
