// Internal: the stages of compress_file (compress.cpp), one file each:
//   read    (compress_read.cpp)   batches of whole fibers from the input,
//                                 cut into tasks for the worker pool;
//   scan    (compress_scan.cpp)   pass 1: counts, bounds, spacing, turns;
//                                 pass 1b when resampling: the new counts;
//   encode  (compress_encode.cpp) pass 2, a pipeline: read a batch of
//                                 fibers -> encode it on the worker pool ->
//                                 write its blocks, the next batch read while
//                                 the pool encodes this one.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "encode/parameters.hpp"
#include "fiblet/block_index.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/error_stats.hpp"
#include "fiblet/fiber_ends.hpp"
#include "fiblet/geometry_error.hpp"
#include "fiblet/resample.hpp"
#include "fiblet/streamline_io.hpp"
#include "container/fft_writer.hpp"

namespace fiblet::detail {

// Adds the seconds from its construction to its destruction to `total`
// (CompressReport::timings; ~20 ns a clock read, taken per fiber or batch).
class StageClock {
public:
    explicit StageClock(double& total) : total_(total) {}
    ~StageClock() { total_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }
    StageClock(const StageClock&) = delete;
    StageClock& operator=(const StageClock&) = delete;

private:
    double& total_;
    std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

// A batch: ~256 k points of whole fibers (at least one fiber; an empty fiber
// counts as one point), cut into tasks of ~16 k points; neither depends on
// the thread count, so no output does.
inline constexpr std::size_t kBatchPoints = std::size_t{1} << 18;
inline constexpr std::size_t kTaskPoints = std::size_t{1} << 14;

struct FiberBatch {
    std::vector<std::vector<Vec3f>> fibers;  // kept between batches: their capacity is reused
    std::size_t count = 0;                   // fibers in this batch
    std::uint32_t first_fiber = 0;
    std::vector<std::size_t> cuts;  // task t has fibers [cuts[t], cuts[t + 1])
    std::size_t points = 0;         // read so far (an empty fiber counts as one)
    bool complete = false;          // no more fibers belong to it
    std::size_t tasks() const { return cuts.empty() ? 0 : cuts.size() - 1; }
};

// The read stage: the next batch of fibers from `reader` (first_fiber: the
// index of its first); false at the end of the input. More than 2^32 - 1
// fibers in all: Error{unsupported} (fiber IDs are 32-bit).
bool read_fiber_batch(StreamlineSource& reader, FiberBatch& b, std::uint32_t first_fiber);
// The same a task at a time: begin_fiber_batch, then read_fiber_task adds
// the next task's fibers (true) until the batch is complete (false), with
// read_fiber_batch's fibers and cuts. With `spare`, each fiber is read into
// a buffer taken from its end (the one added last).
void begin_fiber_batch(FiberBatch& b, std::uint32_t first_fiber);
bool read_fiber_task(StreamlineSource& reader, FiberBatch& b, std::vector<std::vector<Vec3f>>* spare = nullptr);

// The bounds of a fiber's points into min / max (pass 1). Float comparisons
// (exact: the double bounds of floats are floats); NaN coordinates are left
// out; a zero bound is +0.
void add_bounds(std::span<const Vec3f> fiber, double* min, double* max);

// Median of segment lengths from a histogram of their float32 bit patterns
// (the top 13 mantissa bits: 1.2e-4 relative resolution from 1 um up to
// the float range, no logarithm per segment), one block of bins per binary
// exponent, allocated when a length first falls in it: constant, small
// memory. Lengths beyond the float range count as its largest (compress
// refuses extents beyond it, so such a median is at most sqrt(3) times it).
class LengthHistogram {
public:
    // A fiber's segment lengths. A fixed-step fiber's lengths all fall in
    // one bin: they are counted as runs, a bin's count stored once a run
    // (each store of a count waited on the one before: 4 % of an `-e 0`
    // compress), the run's lengths checked four at a time with AVX2.
    void add(std::span<const double> lengths);
    void merge(const LengthHistogram& other);
    double median() const;

private:
    static std::uint32_t bin_of(float f) {
        return std::min<std::uint32_t>((std::bit_cast<std::uint32_t>(f) - kMinBits) >> kShift, kBins - 1);
    }
    void count_run(std::uint32_t bin, std::uint64_t run) {
        if (run == 0) return;
        auto& block = blocks_[bin >> kMantissaBits];
        if (!block) block = std::make_unique<std::uint64_t[]>(kBlock);  // zeroed
        block[bin & (kBlock - 1)] += run;
    }
    static constexpr float kMin = 0x1p-20f;
    static constexpr std::uint32_t kMinBits = std::bit_cast<std::uint32_t>(kMin), kShift = 10;
    static constexpr std::uint32_t kMantissaBits = 23 - kShift, kBlock = 1u << kMantissaBits;
    // Every exponent from kMin's to the largest finite float's: a median of
    // metres or kilometres is that median, not a finer step of millions of points.
    static constexpr std::uint32_t kExponents =
        (std::bit_cast<std::uint32_t>(std::numeric_limits<float>::max()) >> 23) - (kMinBits >> 23) + 1;
    static constexpr std::uint32_t kBins = kExponents * kBlock;  // 2^-20 mm .. FLT_MAX
    std::array<std::unique_ptr<std::uint64_t[]>, kExponents> blocks_;
    std::uint64_t count_ = 0, below_ = 0;
};

// Pass 1: what the scan found besides `scan`'s fields.
struct ScanStageResult {
    std::vector<std::uint32_t> fiber_points;  // per fiber
    TurnStatistics turns;                     // turning angles and the sharpest blocks
    FiberSample sample;                       // fibers for tuning the encoder
    FiberSample bits_sample;                  // more fibers (of 2 points or more), for the direction bits
    LengthHistogram lengths;                  // segment lengths (their median)
    double length_sum = 0;
    std::vector<float> fiber_lengths;  // per fiber: its polyline length (mm), for block_keeping_step
};

// The resampling step for variable-step input whose default step is
// `step`: the smallest step at which no fiber needs more blocks of
// `points_per_block` than at `step` (a fiber of length L is counted
// L / step + 3 points: the first, one a chord, the kept end and one to
// spare), when that is at most kBlockKeepingShrink of `step` (else `step`),
// but no finer than kBlockKeepingFinest of it: at most 4 times the points
// (fibers of a few mm among a file of a few points each would otherwise
// get steps near the anchors' quantum).
// Blocks are fixed-size, so a fiber of few points (raw bundles: 20 a fiber,
// one 60-point block) gets the finer step for no bytes: its chords then
// follow its corners (docs/encode.md, "A finer step for fibers of few points").
inline constexpr double kBlockKeepingShrink = 0.95, kBlockKeepingFinest = 0.25;
double block_keeping_step(std::span<const float> fiber_lengths, double step, std::uint32_t points_per_block);

// Pass 1 over `reader` (from where it stands: its start): fills scan's
// counts, bounds and step extremes (not step_mean/median: from the result).
// `bits_sample_points` 0: no bits sample.
ScanStageResult scan_stage(StreamlineSource& reader, SourceScan& scan, std::uint32_t points_per_block,
                           std::size_t sharp_blocks, std::size_t tuning_points, std::size_t bits_sample_points,
                           unsigned threads, const CompressOptions& options, CompressTimings& timings);

// How pass 1b resamples: the step (mm) and the decoder's stretch of it
// that the length-keeping tension allows for (length_keeping_tension).
struct ResampleStep {
    double step_mm = 0, stretch = 1;
};

// Pass 1b (resampling): each fiber's length-keeping tension into `tensions`
// (in kTensionQuantum units) and its resampled point count into
// fiber_points, the turns of the resampled fibers into `turns` (replaced),
// scan.off_step_segments. A fiber needing more than max_fiber_points:
// Error{unsupported} (the first in file order).
void resample_scan_stage(StreamlineSource& reader, ResampleStep resample, double tolerance,
                         std::size_t max_fiber_points, SourceScan& scan, std::vector<std::uint32_t>& fiber_points,
                         std::vector<std::uint16_t>& tensions, TurnStatistics& turns, std::uint32_t points_per_block,
                         std::size_t sharp_blocks, unsigned threads, const CompressOptions& options,
                         CompressTimings& timings);

// Per-point fields of resampled input, re-made at the resampled points:
// float values as float32, linear between the two input points of the
// piece each lies on (interpolate_point_values); integer values (labels)
// the nearer input point's, in their own type. The other fields are kept
// as read.
class PointFieldResampler {
public:
    // `fields`: null when the input is not resampled; `original_points`:
    // each fiber's input point count.
    PointFieldResampler(std::vector<StreamlineField>* fields, const std::vector<std::uint32_t>& original_points);
    bool active() const { return !columns_.empty(); }
    // Bytes the outputs will take for these resampled point counts.
    double bytes_for(const std::vector<std::uint32_t>& points) const;
    // The resampled point counts are known: size the outputs.
    void set_resampled_points(const std::vector<std::uint32_t>& points);
    // Fiber f was resampled at `positions` (threads write disjoint fibers).
    void resample(std::uint32_t f, std::span<const PolylinePosition> positions);
    void finish();

private:
    struct Column {
        StreamlineField* field;
        bool nearest;                       // integer values: the nearer input point's
        std::vector<float> input, output;   // float values, as float32
        std::vector<std::uint8_t> raw;      // integer values, as read
    };
    std::vector<Column> columns_;
    std::vector<std::uint64_t> original_offsets_, offsets_;
};

// What the encode stage needs besides the input: the encoder, the
// resampling step (0: none), the outputs it fills.
struct EncodeStageInputs {
    const FiberEncoder& encoder;
    double step = 0;                     // resampling step (mm), 0 when not resampled
    PointFieldResampler* point_fields = nullptr;
    FiberEndFractions* end_fractions = nullptr;  // resampled: one per fiber
    const std::vector<std::uint16_t>* tensions = nullptr;  // resampled: pass 1b's, one per fiber
    bool block_index = true;
    unsigned threads = 1;
};

struct EncodeStageResult {
    ErrorStats error;
    GeometryError geometry;
    CompressTimings timings;  // read, encode, metrics, index, write
};

// Pass 2: reads `reader` from its start, encodes every fiber and writes the
// blocks to `out` (with their checksums) and `index` in fiber order. The output does
// not depend on `threads`: batches and tasks are cut by point counts only,
// and each task's statistics are merged in task order.
EncodeStageResult encode_stage(StreamlineSource& reader, const EncodeStageInputs& in, FftWriter& out, IndexBuilder& index,
                               const CompressOptions& options);

}  // namespace fiblet::detail
