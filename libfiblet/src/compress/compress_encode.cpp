// The encode stage of compress_file (compress_stages.hpp): a three-stage
// pipeline over batches of whole fibers,
//
//   read_fiber_batch  the caller's thread parses the next batch of the
//                     input (compress_read.cpp)
//   encode_task       the worker pool encodes the current batch, a task (a
//                     contiguous run of ~16 k points) at a time; ends that
//                     miss their fiber's length are placed again once the
//                     batch's error is known (finish_batch)
//   write_batch       the caller writes the previous batch's blocks,
//                     checksum and index entries, in order
//
// (batch_pipeline.hpp) so reading and writing overlap the encoding, and a
// thread the OS schedules late only takes fewer tasks. Memory is bounded: two batches of
// input (~3 MB each) and their blocks.
#include <cmath>
#include <cstring>
#include <optional>
#include <utility>
#include "compress/batch_pipeline.hpp"
#include "compress/compress_stages.hpp"
#include "encode/fiber_end_encoder.hpp"
#include "core/append_points.hpp"
#include "core/points_avx2.hpp"
#include "core/vec_math.hpp"
#include "fiblet/parallel.hpp"
#include "container/packed_blocks16.hpp"

namespace fiblet::detail {

namespace {

// Fixed-step fibers encoded together: enough that their next length tail
// searches usually fill a vector's lanes (a task's fibers, ~30 of 500
// points, rather than 16 at a time: default compress 3 % faster).
constexpr std::size_t kFibersTogether = 64;

// The header's error of each point: the worse of fiblet's float decode and
// the exact decode (when given), so it holds for every decoder. One square
// root per point (of the larger square: the same double as the larger of
// the two roots), taken by the statistics' pass. e2 holds the float
// decode's squares already where `known` (the symmetric report computed
// them: a fixed-step input is its own targets); the exact decode's points
// are then measured only where they differ from the float decode's (the
// blocks append_exact8 walked in float64; a copy elsewhere).
#ifdef FIBLET_POINTS_AVX2
// The loop of add_point_errors four points at a time: the same double
// operations (distance2's, std::max of non-NaN squares); returns the points
// left to the scalar loop.
__attribute__((target("avx2"))) std::size_t point_errors_avx2(const Vec3f* targets, const Vec3f* decoded,
                                                              const Vec3f* decoded_exact, std::size_t n, double* e2) {
    std::size_t k = 0;
    for (; k + 4 <= n; k += 4) {
        __m256d tx, ty, tz, x, y, z;
        xyz4(targets + k, tx, ty, tz);
        xyz4(decoded + k, x, y, z);
        __m256d worst = norm2(_mm256_sub_pd(tx, x), _mm256_sub_pd(ty, y), _mm256_sub_pd(tz, z));
        if (decoded_exact) {
            xyz4(decoded_exact + k, x, y, z);
            worst = _mm256_max_pd(norm2(_mm256_sub_pd(tx, x), _mm256_sub_pd(ty, y), _mm256_sub_pd(tz, z)), worst);
        }
        _mm256_storeu_pd(e2 + k, worst);
    }
    return k;
}
#endif

bool same_point(const Vec3f& a, const Vec3f& b) { return std::memcmp(&a, &b, sizeof(Vec3f)) == 0; }

void add_point_errors(std::span<const Vec3f> targets, std::span<const Vec3f> decoded,
                      std::span<const Vec3f> decoded_exact, std::uint32_t fiber, bool known, std::vector<double>& e2,
                      ErrorStats& out) {
    const std::size_t n = targets.size();
    if (known) {
        // The exact decode differs in a few blocks: runs of points compared
        // whole, and only the runs that differ point by point.
        constexpr std::size_t kRun = 64;
        for (std::size_t k0 = 0; !decoded_exact.empty() && k0 < n; k0 += kRun) {
            const std::size_t k1 = std::min(n, k0 + kRun);
            if (std::memcmp(&decoded[k0], &decoded_exact[k0], (k1 - k0) * sizeof(Vec3f)) == 0) continue;
            for (std::size_t k = k0; k < k1; ++k)
                if (!same_point(decoded[k], decoded_exact[k]))
                    e2[k] = std::max(e2[k], distance2(targets[k], decoded_exact[k]));
        }
        out.add_all_roots(e2.data(), n, fiber);
        return;
    }
    e2.resize(n);
    std::size_t k = 0;
#ifdef FIBLET_POINTS_AVX2
    if (use_avx2_loops())
        k = point_errors_avx2(targets.data(), decoded.data(), decoded_exact.empty() ? nullptr : decoded_exact.data(), n,
                              e2.data());
#endif
    for (; k < n; ++k) {
        e2[k] = distance2(targets[k], decoded[k]);
        if (!decoded_exact.empty()) e2[k] = std::max(e2[k], distance2(targets[k], decoded_exact[k]));
    }
    out.add_all_roots(e2.data(), n, fiber);
}

// One task's outputs and scratch. Task t of every batch uses slot t of its
// batch's set: statistics accumulate per slot in batch order and are merged
// in slot order at the end, whichever thread ran the task.
struct Slot {
    std::vector<std::uint8_t> blocks;  // in the in-memory layout (the index is of these)
    std::vector<std::uint8_t> packed;  // version 17: the blocks as stored (and checksummed)
    std::vector<std::uint32_t> packed_sizes;  // of each packed block
    // The fibers not measured yet (from first_pending of the batch on), one
    // after the other: targets (resampled fibers), decoded points (both
    // decoders), where each starts, where its blocks end, and its end.
    std::vector<Vec3f> targets, decoded, decoded_exact, resampled, scratch;
    std::vector<std::size_t> starts, block_ends;
    std::vector<FiberEnd> ends;
    std::vector<double> lengths;  // resampled: the input polylines' lengths
    std::size_t first_pending = 0;
    std::vector<PolylinePosition> positions;  // of the resampled points on the input
    std::vector<double> point_errors;         // scratch of add_point_errors
    double kept_max = 0;        // resampled 8-bit: the largest error of the points no end placement moves, mm
    bool ends_missing = false;  // some fiber's length misses by more than its point errors: measured later
    ErrorStats error;
    GeometryError geometry;  // both ways against the input polylines
    IndexBuilder index;      // bounds of this task's blocks (the BIDX chunk)
    CompressTimings timings;  // encode, metrics, index
};

// Resampled fibers whose length the end placement left off by more than
// their own point errors (8-bit blocks: the 0.1 mm bundles' codes zig-zag
// by more than those errors take back; docs/encode.md) get their end placed
// again, allowed `budget`: the largest error of the batch's points that no
// end placement moves, which the file's recorded max error is at least, so
// the ends stay within it. Only the fibers the budget brings closer change.
bool misses_its_length(const FiberEnd& end) { return end.length_miss_mm > end.other_error_mm; }

// The points a fiber's end placement may move: its last, or its last block's anchors.
std::size_t movable_end_points(const FiberEnd& end) {
    return end_fraction_applies(end.last_block_points) ? 1 : end.last_block_points;
}

void place_missing_ends(const EncodeStageInputs& in, const FiberBatch& b, double budget, Slot& w) {
    const std::uint32_t bb = in.encoder.header().block_bytes();
    auto fiber = [&](std::size_t j, std::vector<Vec3f>& v) {
        return std::span<Vec3f>(v).subspan(w.starts[j], w.starts[j + 1] - w.starts[j]);
    };
    for (std::size_t j = 0; j < w.ends.size(); ++j) {
        const FiberEnd& end = w.ends[j];
        if (!misses_its_length(end) || !(end.length_miss_mm > budget) || !(budget > end.other_error_mm)) continue;
        const std::span<Vec3f> exact = w.decoded_exact.empty() ? std::span<Vec3f>() : fiber(j, w.decoded_exact);
        (*in.end_fractions)[b.first_fiber + w.first_pending + j] =
            place_end_within(in.encoder.header(), end, &w.blocks[w.block_ends[j] - bb], fiber(j, w.targets),
                             fiber(j, w.decoded), exact, w.lengths[j], budget);
    }
}

// The pending fibers' statistics and block index, in fiber order; then
// they are no longer pending.
void measure_pending(const EncodeStageInputs& in, const FiberBatch& b, Slot& w) {
    for (std::size_t j = 0; j + 1 < w.starts.size(); ++j) {
        const std::size_t s = w.starts[j], n = w.starts[j + 1] - s, i = w.first_pending + j;
        const std::span<const Vec3f> decoded(w.decoded.data() + s, n);
        const std::span<const Vec3f> points =
            in.step > 0 ? std::span<const Vec3f>(w.targets.data() + s, n) : std::span<const Vec3f>(b.fibers[i]);
        const std::span<const Vec3f> decoded_exact =
            w.decoded_exact.size() == w.decoded.size() ? std::span<const Vec3f>(w.decoded_exact.data() + s, n)
                                                        : std::span<const Vec3f>();
        const auto f = std::uint32_t(b.first_fiber + i);
        if (in.block_index) {
            const StageClock clock(w.timings.index);
            w.index.add_fiber(decoded);
        }
        const StageClock clock(w.timings.metrics);
        const bool known = in.step <= 0;  // fixed-step: the targets are the input's points
        if (known) w.point_errors.resize(n);
        w.geometry.add_fiber(b.fibers[i], decoded, f, known ? std::span<double>(w.point_errors.data(), n) : std::span<double>());
        add_point_errors(points, decoded, decoded_exact, f, known, w.point_errors, w.error);
    }
    w.targets.clear(), w.decoded.clear(), w.decoded_exact.clear();
    w.starts.assign(1, 0), w.block_ends.clear(), w.ends.clear(), w.lengths.clear();
}

void pack_task(const EncodeStageInputs& in, Slot& w) {
    const StageClock clock(w.timings.encode);
    const FftHeader& h = in.encoder.header();
    w.packed.clear();
    w.packed_sizes.clear();
    if (h.packed()) pack_blocks16(h, w.blocks, w.packed, &w.packed_sizes);
}

// Fixed-step fibers [i, end) of the batch, encoded together (their blocks
// and length tails searched in SIMD lanes: FiberEncoder::encode_fibers).
void encode_fixed_step(const EncodeStageInputs& in, const FiberBatch& b, std::size_t i, std::size_t end, Slot& w) {
    const StageClock clock(w.timings.encode);
    std::span<const Vec3f> fibers[kFibersTogether];
    for (std::size_t j = i; j < end; ++j) fibers[j - i] = b.fibers[j];
    std::size_t blocks_end = w.blocks.size();
    in.encoder.encode_fibers(std::span<const std::span<const Vec3f>>(fibers, end - i), std::uint32_t(b.first_fiber + i),
                             w.blocks, &w.decoded, &w.decoded_exact);
    for (std::size_t j = i; j < end; ++j) {
        blocks_end += std::size_t(in.encoder.block_count(b.fibers[j].size())) * in.encoder.header().block_bytes();
        w.starts.push_back(w.starts.back() + b.fibers[j].size());
        w.block_ends.push_back(blocks_end);
    }
}

// Resampled fiber i of the batch, its end placed; its largest error that
// no later end placement moves (8-bit) into the task's budget.
void encode_resampled(const EncodeStageInputs& in, const FiberBatch& b, std::size_t i, Slot& w) {
    const std::vector<Vec3f>& original = b.fibers[i];
    const auto f = std::uint32_t(b.first_fiber + i);
    {
        const StageClock clock(w.timings.encode);
        const bool fields = in.point_fields && in.point_fields->active();
        const std::size_t at = w.targets.size();
        const bool short_tail = resample_cubic_keeping_end(original, in.step, tension_of((*in.tensions)[f]), w.resampled,
                                                           fields ? &w.positions : nullptr, kWrittenCurve);
        if (fields) in.point_fields->resample(f, w.positions);
        append_points(w.targets, w.resampled.data(), w.resampled.size());
        const std::span<const Vec3f> points(w.targets.data() + at, w.targets.size() - at);
        w.lengths.push_back(polyline_length(original));
        w.ends.push_back(encode_keeping_end(in.encoder, points, short_tail, in.step, f, w.blocks, w.decoded,
                                            &w.decoded_exact, w.scratch, w.lengths.back()));
        (*in.end_fractions)[f] = w.ends.back().fraction;
    }
    const std::size_t s = w.starts.back();
    w.starts.push_back(w.decoded.size());
    w.block_ends.push_back(w.blocks.size());
    if (in.encoder.header().direction_bits() != 8) return;
    const StageClock clock(w.timings.metrics);
    const bool missing = misses_its_length(w.ends.back());
    w.ends_missing = w.ends_missing || missing;
    const std::size_t n = w.decoded.size() - s;
    const std::size_t kept = missing ? n - std::min(n, movable_end_points(w.ends.back())) : n;
    auto fiber = [&](const std::vector<Vec3f>& v) { return v.empty() ? std::span<const Vec3f>() : std::span<const Vec3f>(v).subspan(s); };
    w.kept_max = std::max(w.kept_max, largest_error(fiber(w.targets), fiber(w.decoded), fiber(w.decoded_exact), kept));
}

// Stage 2, one task: fibers [cuts[t], cuts[t + 1]) of the batch into the
// slot, measured as soon as they are encoded — but from the first
// resampled fiber that misses its length on, they wait for the batch's
// budget (finish_batch).
void encode_task(const EncodeStageInputs& in, const FiberBatch& b, std::size_t t, Slot& w) {
    // The points of fibers being measured: the buffers this thread used
    // last (in its cache), not the slot's own, last used two batches ago;
    // handed back unless fibers wait in them for finish_batch.
    thread_local std::vector<Vec3f> warm[3];
    std::vector<Vec3f>* points[3] = {&w.targets, &w.decoded, &w.decoded_exact};
    for (int k = 0; k < 3; ++k) points[k]->swap(warm[k]), points[k]->clear();
    w.blocks.clear();
    w.index.clear();
    w.starts.assign(1, 0), w.block_ends.clear(), w.ends.clear(), w.lengths.clear();
    w.kept_max = 0, w.ends_missing = false;
    for (std::size_t i = b.cuts[t]; i < b.cuts[t + 1];) {
        if (w.starts.size() == 1) w.first_pending = i;
        if (in.step > 0) {
            encode_resampled(in, b, i, w);
            ++i;
        } else {
            const std::size_t end = std::min(b.cuts[t + 1], i + kFibersTogether);
            encode_fixed_step(in, b, i, end, w);
            i = end;
        }
        if (!w.ends_missing) measure_pending(in, b, w);
    }
    if (w.ends_missing) return;
    pack_task(in, w);
    for (int k = 0; k < 3; ++k) points[k]->swap(warm[k]);
}

// Stage 2's end on the caller, once a batch's tasks are done: the fibers
// that miss their length get their ends placed within the batch's budget,
// and the tasks that waited are measured (in parallel). The budget depends
// on the batch alone, not on the thread count.
void finish_batch(const EncodeStageInputs& in, const FiberBatch& b, std::vector<Slot>& slots) {
    double budget = 0;
    bool missing = false;
    for (std::size_t t = 0; t < b.tasks(); ++t) budget = std::max(budget, slots[t].kept_max), missing = missing || slots[t].ends_missing;
    if (!missing) return;
    parallel_for(b.tasks(), in.threads, [&](std::size_t t) {
        Slot& w = slots[t];
        if (!w.ends_missing) return;
        {
            const StageClock clock(w.timings.encode);
            place_missing_ends(in, b, budget, w);
        }
        measure_pending(in, b, w);
        pack_task(in, w);
    });
}

// Stage 3: a batch's blocks, checksums and index entries, in task order.
void write_batch(const FiberBatch& b, std::vector<Slot>& slots, FftWriter& out, IndexBuilder& index,
                 CompressTimings& timings) {
    const StageClock clock(timings.write);
    for (std::size_t t = 0; t < b.tasks(); ++t) {
        const Slot& s = slots[t];
        if (s.packed.empty()) out.write_blocks(s.blocks);
        else out.write_packed_blocks(s.packed, s.packed_sizes);
        index.append(slots[t].index);
    }
}

}  // namespace

PointFieldResampler::PointFieldResampler(std::vector<StreamlineField>* fields,
                                         const std::vector<std::uint32_t>& original_points) {
    if (!fields) return;
    for (StreamlineField& f : *fields) {
        if (f.scope() != FieldScope::point) continue;
        Column c{&f, !is_float_type(f.type), {}, {}, {}};
        if (c.nearest) {
            c.raw = std::move(f.bytes);
        } else {
            c.input.resize(std::size_t(f.values()));
            for (std::uint64_t k = 0; k < c.input.size(); ++k)
                c.input[k] = narrow_to_float(field_value(f.type, &f.bytes[k * f.value_size()]));
        }
        columns_.push_back(std::move(c));
    }
    if (columns_.empty()) return;
    original_offsets_.resize(original_points.size() + 1);
    for (std::size_t i = 0; i < original_points.size(); ++i)
        original_offsets_[i + 1] = original_offsets_[i] + original_points[i];
}

double PointFieldResampler::bytes_for(const std::vector<std::uint32_t>& points) const {
    double rows = 0, total = 0;  // doubles: no product can overflow
    for (const std::uint32_t n : points) rows += n;
    for (const Column& c : columns_)
        total += rows * double(c.field->components) * double(c.nearest ? c.field->value_size() : sizeof(float));
    return total;
}

void PointFieldResampler::set_resampled_points(const std::vector<std::uint32_t>& points) {
    if (!active()) return;
    offsets_.assign(points.size() + 1, 0);
    for (std::size_t i = 0; i < points.size(); ++i) offsets_[i + 1] = offsets_[i] + points[i];
    for (Column& c : columns_) {
        const std::size_t values = std::size_t(offsets_.back()) * c.field->components;
        if (c.nearest) c.field->bytes.assign(values * c.field->value_size(), 0);
        else c.output.resize(values);
    }
}

void PointFieldResampler::resample(std::uint32_t f, std::span<const PolylinePosition> positions) {
    for (Column& c : columns_) {
        const std::size_t n = c.field->components;
        if (!c.nearest) {
            interpolate_point_values(positions, &c.input[original_offsets_[f] * n], n, &c.output[offsets_[f] * n]);
            continue;
        }
        const std::size_t row = n * c.field->value_size();
        for (std::size_t k = 0; k < positions.size(); ++k) {
            const std::size_t nearer = positions[k].segment + (positions[k].t > 0.5 ? 1 : 0);
            std::memcpy(&c.field->bytes[(offsets_[f] + k) * row], &c.raw[(original_offsets_[f] + nearer) * row], row);
        }
    }
}

// Each column's arrays are released as soon as its field holds the values:
// the peak stays within the budget's two copies (compress.cpp), the values
// and the DATA chunk made of them.
void PointFieldResampler::finish() {
    for (Column& c : columns_) {
        if (c.nearest) {
            std::vector<std::uint8_t>().swap(c.raw);
            continue;
        }
        std::vector<float>().swap(c.input);
        StreamlineField& f = *c.field;
        f.type = FieldType::float32;
        f.bytes.resize(c.output.size() * 4);
        std::memcpy(f.bytes.data(), c.output.data(), f.bytes.size());
        std::vector<float>().swap(c.output);
    }
}

EncodeStageResult encode_stage(StreamlineSource& reader, const EncodeStageInputs& in, FftWriter& out, IndexBuilder& index,
                               const CompressOptions& options) {
    reader.rewind();
    EncodeStageResult r;
    std::vector<Slot> slots[2];
    const IndexBuilder empty_index = index;  // the file's layout, no blocks yet
    for_each_batch(
        reader, in.threads, slots, [&](Slot& s) { s.index = empty_index; },
        [&](const FiberBatch& b, std::size_t t, Slot& s) { encode_task(in, b, t, s); },
        [](const FiberBatch&, std::size_t, std::size_t) {},
        [&](const FiberBatch& b, std::vector<Slot>& batch_slots) {
            finish_batch(in, b, batch_slots);
            write_batch(b, batch_slots, out, index, r.timings);
            if (options.progress && reader.data_bytes() > 0)
                options.progress("encode", double(reader.bytes_consumed()) / double(reader.data_bytes()));
        },
        in.step > 0,  // a resampled fiber's end may wait for the batch's budget (finish_batch)
        r.timings.read);

    for (int k = 0; k < 2; ++k)
        for (const Slot& w : slots[k]) {
            r.error.merge(w.error), r.geometry.merge(w.geometry);
            r.timings += w.timings;
        }
    return r;
}

}  // namespace fiblet::detail
