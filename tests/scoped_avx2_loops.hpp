// The library's AVX2 loops (and the AVX-512 ones, which need them) switched
// on or off on this thread for a scope (core/points_avx2.hpp).
#pragma once

#include "core/points_avx2.hpp"

namespace fiblet::test {

class ScopedAvx2Loops {
public:
    explicit ScopedAvx2Loops(bool on) : was_(detail::avx2_loops_enabled()) { detail::avx2_loops_enabled() = on; }
    ~ScopedAvx2Loops() { detail::avx2_loops_enabled() = was_; }
    ScopedAvx2Loops(const ScopedAvx2Loops&) = delete;
    ScopedAvx2Loops& operator=(const ScopedAvx2Loops&) = delete;

private:
    bool was_;
};

}  // namespace fiblet::test
