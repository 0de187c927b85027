// What the benchmark programs share: tractograms in memory, the baseline
// codecs the table compares fiblets with (float16 positions, a sequential
// decoder without blocks), and error measurement.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fiblet/fft_format.hpp"

namespace fiblet::bench {

// Points in the TRX layout (as fiblet::Streamlines).
struct Tractogram {
    std::vector<float> xyz;
    std::vector<std::uint64_t> offsets{0};
    std::size_t fibers() const { return offsets.size() - 1; }
    std::size_t points() const { return offsets.back(); }
};

// The whole .tck through fiblet's TckReader into `out` (cleared; its
// storage is reused, so a warm second call measures parsing alone).
void read_tck(const std::string& path, Tractogram& out);

// The shared tractogram the micro-benchmarks use: $FIBLET_BENCH_TCK, or
// ../shared/data/small-ifod1.tck.
std::string default_bench_tck();

// Max and mean distance (mm) between corresponding points.
struct PointErrors {
    double max_mm = 0, mean_mm = 0;
};
PointErrors point_errors(const std::vector<float>& a, const std::vector<float>& b);

// float16 positions (TRX's lossy choice): F16C when the CPU has it.
void to_half(const float* in, std::uint16_t* out, std::size_t n);
void from_half(const std::uint16_t* in, float* out, std::size_t n);

// "QFib-style" sequential coding without blocks: the fiblet recurrence over
// a whole fiber (two float32 anchors, then one 8-bit direction per point,
// closed loop), so a fiber is one serial chain. Layout: per fiber a u32
// point count, the first two points as float32 (as many as the fiber has),
// then one code per further point.
struct SequentialCoded {
    float step_mm = 0, ratio = 1;
    std::vector<std::uint8_t> bytes;
    std::size_t fibers = 0, points = 0;
};
SequentialCoded encode_sequential(const Tractogram& t);
// Decodes into `out` (sized by the caller: 3 floats per point).
void decode_sequential(const SequentialCoded& coded, float* out);

}  // namespace fiblet::bench
