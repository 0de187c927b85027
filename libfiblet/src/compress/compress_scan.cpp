// The scan stage of compress_file (compress_stages.hpp): pass 1 (counts,
// bounds, spacing, turning angles) and, when resampling, pass 1b (the
// resampled counts and turns). Both are pipelines over batches of whole
// fibers (batch_pipeline.hpp): the caller's thread reads the next batch
// (read_fiber_batch) and does the per-fiber bookkeeping that must follow the
// file's order while the worker pool measures the current batch, a task at
// a time. Each task
// index has its own partial statistics (one set per batch parity), merged in
// index order at the end: the result does not depend on the thread count.
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>

#include "compress/batch_pipeline.hpp"
#include "compress/compress_stages.hpp"
#include "core/points_avx2.hpp"
#include "core/sum_lanes.hpp"
#include "core/streamline_label.hpp"
#include "fiblet/error.hpp"
#include "core/vec_math.hpp"
#include "fiblet/parallel.hpp"

namespace fiblet::detail {

namespace {

void report_progress(const CompressOptions& o, const char* phase, const StreamlineSource& r) {
    if (o.progress && r.data_bytes() > 0) o.progress(phase, double(r.bytes_consumed()) / double(r.data_bytes()));
}

// What compress keeps per streamline until the file is written (counts,
// lengths, ends, the index's and the output's tables; the TRX offsets):
// 31.5 bytes measured on TRX files of 2^20 to 2^22 empty streamlines.
constexpr double kTableBytesPerFiber = 32;

// Streamlines cost memory however few points they have (2^24 empty ones
// fit in a 64 kB TRX): their tables are sized against the budget as the
// scan counts them, before they grow past it.
void check_fiber_tables(const StreamlineSource& r, std::uint64_t fibers, const CompressOptions& o) {
    const std::uint64_t budget = o.max_memory ? o.max_memory : default_memory_budget();
    if (double(fibers) * kTableBytesPerFiber <= double(budget)) return;
    throw Error(Errc::unsupported,
                r.path() + ": " + std::to_string(fibers) + " streamlines and counting: their tables (about " +
                    std::to_string(int(kTableBytesPerFiber)) + " bytes each) would take more than the memory budget of " +
                    std::to_string(budget >> 20) + " MiB",
                Remedy::max_memory);
}

// Pass 1's partial statistics of one task index.
struct ScanSlot {
    double min[3] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                     std::numeric_limits<double>::infinity()};
    double max[3] = {-min[0], -min[1], -min[2]};
    double step_min = std::numeric_limits<double>::infinity(), step_max = 0, length_sum = 0;
    std::uint64_t segments = 0;
    LengthHistogram lengths;
    std::optional<TurnStatistics> turns;
    std::vector<float> fiber_lengths;  // of this task's fibers in the current batch
    double seconds = 0;                // in scan_task
};

// lo = min(lo, lengths), hi = max(hi, lengths), in four lanes (a loop the
// compiler vectorizes; the lengths are not NaN, so the lanes' order does
// not matter).
void step_range(std::span<const double> lengths, double& lo, double& hi) {
    double mn[4] = {lo, lo, lo, lo}, mx[4] = {hi, hi, hi, hi};
    std::size_t i = 0;
    for (; i + 4 <= lengths.size(); i += 4)
        for (int j = 0; j < 4; ++j) mn[j] = std::min(mn[j], lengths[i + j]), mx[j] = std::max(mx[j], lengths[i + j]);
    for (; i < lengths.size(); ++i) mn[0] = std::min(mn[0], lengths[i]), mx[0] = std::max(mx[0], lengths[i]);
    lo = std::min(std::min(mn[0], mn[1]), std::min(mn[2], mn[3]));
    hi = std::max(std::max(mx[0], mx[1]), std::max(mx[2], mx[3]));
}

void scan_task(const FiberBatch& b, std::size_t t, ScanSlot& s) {
    const StageClock clock(s.seconds);
    double length_sum = 0;  // this task's, added to the slot's once (the same sums whatever the threads)
    thread_local FiberSegments segments;  // of a fiber, shared with the turn statistics
    const std::vector<double>& lengths = segments.length;
    s.fiber_lengths.clear();
    for (std::size_t i = b.cuts[t]; i < b.cuts[t + 1]; ++i) {
        const std::vector<Vec3f>& fiber = b.fibers[i];
        add_bounds(fiber, s.min, s.max);
        fiber_segments(fiber, segments);
        s.lengths.add(lengths);
        const double fiber_length = sum_in_four_lanes(lengths.data(), lengths.size());
        step_range(lengths, s.step_min, s.step_max);
        length_sum += fiber_length;
        s.fiber_lengths.push_back(float(fiber_length));
        s.segments += lengths.size();
        s.turns->add_fiber(fiber, segments);
    }
    s.length_sum += length_sum;
}

// Pass 1b's partial statistics of one task index.
struct ResampleSlot {
    std::vector<Vec3f> resampled;
    std::optional<TurnStatistics> turns;
    std::uint64_t off_step_segments = 0;
    std::optional<std::uint64_t> too_long;  // the first fiber of this batch's task needing > 65535 blocks
    double too_long_mm = 0;
    double seconds = 0;  // in the task
};

}  // namespace

void add_bounds(std::span<const Vec3f> fiber, double* min, double* max) {
    constexpr float inf = std::numeric_limits<float>::infinity();
    float lo[3] = {inf, inf, inf}, hi[3] = {-inf, -inf, -inf};
    std::size_t k = 0;
#ifdef FIBLET_POINTS_AVX2
    if (use_avx2_loops()) k = bounds_avx2(fiber.data(), fiber.size(), lo, hi);
#endif
    for (; k < fiber.size(); ++k) {
        const Vec3f& p = fiber[k];
        lo[0] = p.x < lo[0] ? p.x : lo[0], lo[1] = p.y < lo[1] ? p.y : lo[1], lo[2] = p.z < lo[2] ? p.z : lo[2];
        hi[0] = p.x > hi[0] ? p.x : hi[0], hi[1] = p.y > hi[1] ? p.y : hi[1], hi[2] = p.z > hi[2] ? p.z : hi[2];
    }
    // + 0.0: a zero bound is +0 whichever of +0 and -0 came first (or in which lane).
    for (int a = 0; a < 3; ++a)
        min[a] = std::min(min[a], double(lo[a]) + 0.0), max[a] = std::max(max[a], double(hi[a]) + 0.0);
}

#ifdef FIBLET_POINTS_AVX2
namespace {
// The end of the run of lengths from k on whose bin is `bin` (all at least
// kMin as floats), four at a time: the same float conversion and bits.
__attribute__((target("avx2"))) std::size_t run_end_avx2(const double* lengths, std::size_t k, std::size_t n,
                                                         std::uint32_t bin, float min, std::uint32_t min_bits,
                                                         int shift, std::uint32_t last_bin) {
    const __m128i want = _mm_set1_epi32(std::int32_t(bin)), base = _mm_set1_epi32(std::int32_t(min_bits)),
                  last = _mm_set1_epi32(std::int32_t(last_bin));
    const __m128 lowest = _mm_set1_ps(min);
    for (; k + 4 <= n; k += 4) {
        const __m128 f = _mm256_cvtpd_ps(_mm256_loadu_pd(lengths + k));
        const __m128i at = _mm_min_epu32(_mm_srl_epi32(_mm_sub_epi32(_mm_castps_si128(f), base), _mm_cvtsi32_si128(shift)), last);
        const __m128i same = _mm_and_si128(_mm_castps_si128(_mm_cmpge_ps(f, lowest)), _mm_cmpeq_epi32(at, want));
        if (_mm_movemask_epi8(same) != 0xffff) break;
    }
    return k;
}
}  // namespace
#endif

void LengthHistogram::add(std::span<const double> lengths) {
    // The counts are locals while the bins are incremented: as members they
    // would be reloaded after every bin's store (both are uint64_t, so the
    // compiler must assume they alias).
    std::uint64_t below = 0, run = 0;
    std::uint32_t run_bin = 0;
    const std::size_t n = lengths.size();
    for (std::size_t k = 0; k < n; ++k) {
        const float f = float(lengths[k]);
        if (!(f >= kMin)) {
            ++below;
            continue;
        }
        const std::uint32_t i = bin_of(f);
        if (i != run_bin) count_run(run_bin, run), run_bin = i, run = 0;
        ++run;
#ifdef FIBLET_POINTS_AVX2
        if (use_avx2_loops()) {
            const std::size_t end = run_end_avx2(lengths.data(), k + 1, n, run_bin, kMin, kMinBits, int(kShift), kBins - 1);
            run += end - (k + 1), k = end - 1;
        }
#endif
    }
    count_run(run_bin, run);
    count_ += n, below_ += below;
}

void LengthHistogram::merge(const LengthHistogram& o) {
    count_ += o.count_, below_ += o.below_;
    for (std::uint32_t e = 0; e < kExponents; ++e) {
        if (!o.blocks_[e]) continue;
        if (!blocks_[e]) blocks_[e] = std::make_unique<std::uint64_t[]>(kBlock);
        for (std::uint32_t j = 0; j < kBlock; ++j) blocks_[e][j] += o.blocks_[e][j];
    }
}

double LengthHistogram::median() const {
    std::uint64_t seen = below_;
    if (count_ == 0 || 2 * seen >= count_) return 0.0;
    for (std::uint32_t e = 0; e < kExponents; ++e) {
        if (!blocks_[e]) continue;
        for (std::uint32_t j = 0; j < kBlock; ++j) {
            seen += blocks_[e][j];
            if (2 * seen >= count_) {
                const std::uint32_t lo = kMinBits + ((e * kBlock + j) << kShift);
                // The top bin's end is infinity: its centre, the float range's end.
                const std::uint32_t hi = std::min(lo + (1u << kShift), std::bit_cast<std::uint32_t>(std::numeric_limits<float>::max()));
                return 0.5 * (double(std::bit_cast<float>(lo)) + double(std::bit_cast<float>(hi)));
            }
        }
    }
    return 0.0;
}

ScanStageResult scan_stage(StreamlineSource& reader, SourceScan& scan, std::uint32_t points_per_block,
                           std::size_t sharp_blocks, std::size_t tuning_points, std::size_t bits_sample_points,
                           unsigned threads, const CompressOptions& options, CompressTimings& timings) {
    ScanStageResult r{.fiber_points = {},
                      .turns = TurnStatistics(points_per_block, sharp_blocks),
                      .sample = FiberSample(tuning_points),
                      .bits_sample = FiberSample(bits_sample_points),
                      .lengths = {}};
    std::vector<ScanSlot> slots[2];
    for_each_batch(
        reader, threads, slots, [&](ScanSlot& s) { s.turns.emplace(points_per_block, sharp_blocks); }, scan_task,
        [&](const FiberBatch& b, std::size_t first, std::size_t end) {  // in file order, on the caller's thread
            for (std::size_t i = first; i < end; ++i) {
                const std::vector<Vec3f>& fiber = b.fibers[i];
                if (fiber.size() > std::numeric_limits<std::uint32_t>::max())
                    throw Error(Errc::unsupported, reader.path() + ": a streamline with more than 2^32 points");
                ++scan.fibers;
                scan.points += fiber.size();
                scan.empty_fibers += fiber.empty();
                scan.single_point_fibers += fiber.size() == 1;
                r.fiber_points.push_back(std::uint32_t(fiber.size()));
                r.sample.offer(fiber);
                // Fibers with a length only: 2^21 empty fibers would otherwise all be kept (48 MB).
                if (bits_sample_points && fiber.size() >= 2) r.bits_sample.offer(fiber);
            }
        },
        [&](const FiberBatch& b, const std::vector<ScanSlot>& done) {
            for (std::size_t t = 0; t < b.tasks(); ++t)  // task order is file order
                r.fiber_lengths.insert(r.fiber_lengths.end(), done[t].fiber_lengths.begin(), done[t].fiber_lengths.end());
            check_fiber_tables(reader, scan.fibers, options);
            report_progress(options, "scan", reader);
        },
        false, timings.read);
    // Merged in slot order: the same sums whatever the thread count.
    scan.min = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                std::numeric_limits<double>::infinity()};
    scan.max = {-scan.min[0], -scan.min[1], -scan.min[2]};
    scan.step_min = std::numeric_limits<double>::infinity();
    scan.step_max = 0;
    double length_sum = 0;
    for (int k = 0; k < 2; ++k)
        for (const ScanSlot& s : slots[k]) {
            for (int a = 0; a < 3; ++a) scan.min[a] = std::min(scan.min[a], s.min[a]), scan.max[a] = std::max(scan.max[a], s.max[a]);
            scan.step_min = std::min(scan.step_min, s.step_min);
            scan.step_max = std::max(scan.step_max, s.step_max);
            scan.segments += s.segments;
            length_sum += s.length_sum;
            r.lengths.merge(s.lengths);
            r.turns.merge(*s.turns);
            timings.scan += s.seconds;
        }
    r.length_sum = length_sum;
    return r;
}

double block_keeping_step(std::span<const float> fiber_lengths, double step, std::uint32_t points_per_block) {
    if (!(step > 0) || points_per_block < 4) return step;
    double finest = 0;
    for (const float len : fiber_lengths) {
        if (!(len > 0)) continue;
        // Its blocks at `step` counted low (chords 0.1 % short of its
        // length, the first point and the kept end), so that a fiber near a
        // block's end never gets a block more; then the smallest s with
        // floor(len / s) + 3 points in as many blocks.
        const double blocks = std::ceil((std::floor(len * (1 - 1e-3) / step) + 2) / points_per_block);
        const double room = points_per_block * blocks - 3;
        finest = std::max(finest, double(len) / (room + 1) * (1 + 1e-9));
    }
    if (!(finest > 0 && finest <= kBlockKeepingShrink * step)) return step;
    return std::max(finest, kBlockKeepingFinest * step);
}

void resample_scan_stage(StreamlineSource& reader, ResampleStep resample, double tolerance,
                         std::size_t max_fiber_points, SourceScan& scan, std::vector<std::uint32_t>& fiber_points,
                         std::vector<std::uint16_t>& tensions, TurnStatistics& turns, std::uint32_t points_per_block,
                         std::size_t sharp_blocks, unsigned threads, const CompressOptions& options,
                         CompressTimings& timings) {
    const double step = resample.step_mm;
    reader.rewind();
    std::vector<ResampleSlot> slots[2];
    auto task = [&](const FiberBatch& b, std::size_t t, ResampleSlot& s) {
        const StageClock clock(s.seconds);
        s.too_long.reset();
        for (std::size_t i = b.cuts[t]; i < b.cuts[t + 1]; ++i) {
            const std::vector<Vec3f>& fiber = b.fibers[i];
            const std::uint64_t f = b.first_fiber + i;
            const double fiber_length = polyline_length(fiber);
            if (!(fiber_length / step < double(max_fiber_points))) {
                s.too_long = f, s.too_long_mm = fiber_length;
                return;  // reported in fiber order by the caller
            }
            const double tension = length_keeping_tension(fiber, step, resample.stretch, kWrittenCurve);
            tensions[f] = tension_code(tension);
            const bool short_tail = resample_cubic_keeping_end(fiber, step, tension, s.resampled, nullptr, kWrittenCurve);
            fiber_points[f] = std::uint32_t(s.resampled.size());
            // The turn towards a kept end is one step per fiber, often a
            // noisy short one: left out of the turn statistics, so the cap
            // (sized for the whole-step turns) stays as fine as before.
            s.turns->add_fiber(std::span<const Vec3f>(s.resampled).first(s.resampled.size() - short_tail));
            for (std::size_t k = 1; k < fiber.size(); ++k)
                s.off_step_segments += std::fabs(distance(fiber[k - 1], fiber[k]) - step) > tolerance * step;
        }
    };
    for_each_batch(
        reader, threads, slots, [&](ResampleSlot& s) { s.turns.emplace(points_per_block, sharp_blocks); }, task,
        [](const FiberBatch&, std::size_t, std::size_t) {},
        [&](const FiberBatch& b, const std::vector<ResampleSlot>& batch_slots) {
            for (std::size_t t = 0; t < b.tasks(); ++t)
                if (const ResampleSlot& s = batch_slots[t]; s.too_long)
                    throw Error(Errc::unsupported, reader.path() + ": " + streamline_label(*s.too_long) + " (" +
                                                       std::to_string(s.too_long_mm) + " mm) needs more than 65535 blocks at a " +
                                                       std::to_string(step) + " mm step");
            report_progress(options, "resample-scan", reader);
        },
        false, timings.read);
    turns = TurnStatistics(points_per_block, sharp_blocks);
    for (int k = 0; k < 2; ++k)
        for (const ResampleSlot& s : slots[k]) {
            turns.merge(*s.turns);
            scan.off_step_segments += s.off_step_segments;
            timings.scan += s.seconds;
        }
}

}  // namespace fiblet::detail
