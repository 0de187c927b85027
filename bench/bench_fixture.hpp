// The data the micro-benchmarks share: the bench tractogram in memory,
// compressed (once, into a temporary directory removed at exit) and its
// blocks read back.
#pragma once

#include <string>
#include <vector>

#include "bench_data.hpp"
#include "fiblet/fft_format.hpp"

namespace fiblet::bench {

struct Fixture {
    Fixture();
    ~Fixture();
    std::string dir, tck, fft;
    Tractogram tractogram;
    FftHeader header;
    std::vector<std::uint8_t> blocks;
    std::size_t points = 0;
};

const Fixture& fixture();

}  // namespace fiblet::bench
