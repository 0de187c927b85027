// Decoding a contiguous range of fibers straight into memory that numpy will
// own (a PopulatedBuffer), on several threads: the Python module's fast path
// for fiblet.load() of a whole file or a range.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "fiblet/fft_file.hpp"
#include "fiblet/fiber_regions.hpp"
#include "populated_buffer.hpp"

namespace fiblet::python {

struct DecodedRange {
    PopulatedBuffer xyz;                    // 3 floats per point
    std::vector<std::uint64_t> offsets{0};  // fiber i: points [offsets[i], offsets[i+1])
    std::uint64_t points = 0;
};

// Fibers [begin, end) of `file`; `threads` = 0 uses all cores. The points are
// those of fiblet::decode_fibers (tests compare them).
DecodedRange decode_range(const FftFile& file, std::uint64_t begin, std::uint64_t end, unsigned threads);

// The fibers among `candidates` that `test` keeps (FiberRegionTest::decode_kept_into),
// their indices into `fibers`.
DecodedRange decode_kept(const FftFile& file, const FiberRegionTest& test, std::span<const FiberRange> candidates,
                         unsigned threads, std::vector<std::uint64_t>& fibers);

}  // namespace fiblet::python
