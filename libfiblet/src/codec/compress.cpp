// The compression pipeline: .tck/.trk/TRX -> scan -> (resample) -> encode -> .fft.
// Streams the input (two or three passes over it, one streamline in memory
// at a time); the output is written atomically.
#include "fiblet/compress.hpp"

#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <span>
#include <thread>
#include <utility>

#include "codec/fiber_end_encoder.hpp"
#include "codec/parameters.hpp"
#include "core/streamline_label.hpp"
#include "core/thread_count.hpp"
#include "fiblet/block_index.hpp"
#include "fiblet/checksum.hpp"
#include "io/fft_sink.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fiber_ends.hpp"
#include "fiblet/output_file.hpp"
#include "fiblet/resample.hpp"
#include "fiblet/streamline_data_chunk.hpp"
#include "fiblet/streamline_io.hpp"
#include "fiblet/tractogram_format.hpp"

namespace fiblet {

namespace {

// Median of segment lengths from a histogram of their float32 bit patterns
// (the top 13 mantissa bits: 1.2e-4 relative resolution between 1 um and
// 2 m, no logarithm per segment), one block of bins per binary exponent,
// allocated when a length first falls in it: constant, small memory.
class LengthHistogram {
public:
    void add(double len) {
        const float f = float(len);
        ++count_;
        if (!(f >= kMin)) return ++below_, void();
        const std::uint32_t i = std::min<std::uint32_t>((std::bit_cast<std::uint32_t>(f) - kMinBits) >> kShift, kBins - 1);
        auto& block = blocks_[i >> kMantissaBits];
        if (!block) block = std::make_unique<std::uint64_t[]>(kBlock);  // zeroed
        ++block[i & (kBlock - 1)];
    }
    double median() const {
        std::uint64_t seen = below_;
        if (count_ == 0 || 2 * seen >= count_) return 0.0;
        for (std::uint32_t e = 0; e < kExponents; ++e) {
            if (!blocks_[e]) continue;
            for (std::uint32_t j = 0; j < kBlock; ++j) {
                seen += blocks_[e][j];
                if (2 * seen >= count_) {
                    const std::uint32_t lo = kMinBits + ((e * kBlock + j) << kShift);
                    return 0.5 * (double(std::bit_cast<float>(lo)) + double(std::bit_cast<float>(lo + (1u << kShift))));
                }
            }
        }
        return 0.0;
    }

private:
    static constexpr float kMin = 0x1p-20f;
    static constexpr std::uint32_t kMinBits = std::bit_cast<std::uint32_t>(kMin), kShift = 10;
    static constexpr std::uint32_t kMantissaBits = 23 - kShift, kBlock = 1u << kMantissaBits;
    static constexpr std::uint32_t kExponents = 31, kBins = kExponents * kBlock;  // 2^-20 .. 2^11 mm
    std::array<std::unique_ptr<std::uint64_t[]>, kExponents> blocks_;
    std::uint64_t count_ = 0, below_ = 0;
};

// A number as printf's %g writes it (std::to_string prints 1e25 in full).
std::string fmt_g(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

double length(Vec3f a, Vec3f b) {
    const double dx = double(b.x) - a.x, dy = double(b.y) - a.y, dz = double(b.z) - a.z;
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}

struct Timer {
    std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
    double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); }
};

void report_progress(const CompressOptions& o, const char* phase, const StreamlineSource& r) {
    if (o.progress && r.data_bytes() > 0) o.progress(phase, double(r.bytes_consumed()) / double(r.data_bytes()));
}

// The decoder walks in float normalized coordinates and starts each block
// from 16-bit anchors. A step below 2^-20 of the extent (points 1e25 mm
// apart in a file stepping 0.1 mm) is lost in that arithmetic: each step's
// rounding is 3 % of it and one anchor quantum spans 16 steps, so the
// decoded fibers would be noise. Refuse such input rather than write it.
constexpr double kMinNormalizedStep = 0x1p-20;

void check_step_resolvable(const std::string& path, double step_mm, double extent_mm, float normalized_step) {
    if (!(step_mm > 0) || double(normalized_step) >= kMinNormalizedStep) return;
    throw Error(Errc::invalid_input,
                path + ": the points span " + fmt_g(extent_mm) + " mm for a " + fmt_g(step_mm) +
                    " mm step: beyond the 2^20 steps per extent that the format's float decoder and 16-bit anchors resolve");
}

// Per-point fields of resampled input, re-made at the resampled points
// (float32, linear between the two input points of the piece each lies on:
// interpolate_point_values);
// the other fields are kept as read.
class PointFieldResampler {
public:
    // `fields`: null when the input is not resampled; `original_points`:
    // each fiber's input point count.
    PointFieldResampler(std::vector<StreamlineField>* fields, const std::vector<std::uint32_t>& original_points) {
        if (!fields) return;
        for (StreamlineField& f : *fields)
            if (f.scope() == FieldScope::point) point_fields_.push_back(&f);
        if (point_fields_.empty()) return;
        original_offsets_.resize(original_points.size() + 1);
        for (std::size_t i = 0; i < original_points.size(); ++i)
            original_offsets_[i + 1] = original_offsets_[i] + original_points[i];
        for (StreamlineField* f : point_fields_) {
            std::vector<float> v(std::size_t(f->values()));
            for (std::uint64_t k = 0; k < v.size(); ++k) v[k] = narrow_to_float(field_value(f->type, &f->bytes[k * f->value_size()]));
            input_.push_back(std::move(v));
        }
    }
    bool active() const { return !point_fields_.empty(); }
    // The resampled point counts are known: size the outputs.
    void set_resampled_points(const std::vector<std::uint32_t>& points) {
        if (!active()) return;
        offsets_.assign(points.size() + 1, 0);
        for (std::size_t i = 0; i < points.size(); ++i) offsets_[i + 1] = offsets_[i] + points[i];
        for (StreamlineField* f : point_fields_) output_.emplace_back(std::size_t(offsets_.back()) * f->components);
    }
    // Fiber f was resampled at `positions` (threads write disjoint fibers).
    void resample(std::uint32_t f, std::span<const PolylinePosition> positions) {
        for (std::size_t i = 0; i < point_fields_.size(); ++i) {
            const std::size_t c = point_fields_[i]->components;
            interpolate_point_values(positions, &input_[i][original_offsets_[f] * c], c, &output_[i][offsets_[f] * c]);
        }
    }
    void finish() {
        for (std::size_t i = 0; i < point_fields_.size(); ++i) {
            StreamlineField& f = *point_fields_[i];
            f.type = FieldType::float32;
            f.bytes.resize(output_[i].size() * 4);
            std::memcpy(f.bytes.data(), output_[i].data(), f.bytes.size());
        }
    }

private:
    std::vector<StreamlineField*> point_fields_;
    std::vector<std::uint64_t> original_offsets_, offsets_;
    std::vector<std::vector<float>> input_, output_;
};

}  // namespace

CompressReport compress_tck(const std::string& tck_path, const std::string& fft_path, const CompressOptions& options) {
    const Timer timer;
    if (options.direction_bits != 8 && options.direction_bits != 16)
        throw Error(Errc::invalid_argument, "direction bits must be 8 or 16");
    const bool wide = options.direction_bits == 16;
    const std::uint32_t points_per_block =
        options.points_per_block ? options.points_per_block : (wide ? kDefaultPointsPerBlock16 : kDefaultPointsPerBlock);
    const std::uint32_t max_points_per_block = wide ? kMaxPointsPerBlock16 : kMaxPointsPerBlock;
    if (points_per_block < 2 || points_per_block > max_points_per_block)
        throw Error(Errc::invalid_argument, "points per block must be in [2, " + std::to_string(max_points_per_block) + "]");
    if (options.step_mm && !(std::isfinite(*options.step_mm) && *options.step_mm > 0))
        throw Error(Errc::invalid_argument, "--step must be a positive number of millimetres");
    const unsigned threads = detail::resolve_threads(options.threads);  // checked before any work

    CompressReport report;
    TckScan& scan = report.scan;
    // The longest streamline a file can hold bounds the one in memory too.
    const std::size_t max_fiber_points = std::size_t{0xffff} * points_per_block;
    const auto source = open_streamline_source(
        tck_path, {.allow_count_mismatch = options.allow_count_mismatch, .max_points = max_fiber_points});
    StreamlineSource& reader = *source;
    scan.header_step = reader.step_size();
    AtomicOutputFile::check_destination(fft_path, options.overwrite);  // before the passes, not after

    // Pass 1: counts, bounding box, spacing, turning angles.
    std::vector<std::uint32_t> fiber_points;
    std::vector<Vec3f> fiber, resampled;
    LengthHistogram lengths;
    // Turning angles and a sample of fibers, for the encoder's choices (parameters.cpp).
    constexpr std::size_t kSharpBlocks = 32;
    detail::TurnStatistics turns(points_per_block, kSharpBlocks);
    detail::FiberSample sample(options.tuning_points);
    double length_sum = 0;
    scan.min = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                std::numeric_limits<double>::infinity()};
    scan.max = {-scan.min[0], -scan.min[1], -scan.min[2]};
    scan.step_min = std::numeric_limits<double>::infinity();
    scan.step_max = 0;
    while (reader.next(fiber)) {
        if (scan.fibers == std::numeric_limits<std::uint32_t>::max())
            throw Error(Errc::unsupported, tck_path + ": more than 2^32 - 1 streamlines (fiber IDs are 32-bit)");
        ++scan.fibers;
        scan.points += fiber.size();
        scan.empty_fibers += fiber.empty();
        scan.single_point_fibers += fiber.size() == 1;
        if (fiber.size() > std::numeric_limits<std::uint32_t>::max())
            throw Error(Errc::unsupported, tck_path + ": a streamline with more than 2^32 points");
        fiber_points.push_back(std::uint32_t(fiber.size()));
        for (std::size_t i = 0; i < fiber.size(); ++i) {
            const Vec3f p = fiber[i];
            const double c[3] = {p.x, p.y, p.z};
            for (int a = 0; a < 3; ++a) scan.min[a] = std::min(scan.min[a], c[a]), scan.max[a] = std::max(scan.max[a], c[a]);
            if (i > 0) {
                const double len = length(fiber[i - 1], p);
                lengths.add(len);
                length_sum += len;
                scan.step_min = std::min(scan.step_min, len);
                scan.step_max = std::max(scan.step_max, len);
                ++scan.segments;
            }
        }
        turns.add_fiber(fiber);
        sample.offer(fiber);
        if ((scan.fibers & 1023) == 0) report_progress(options, "scan", reader);
    }
    std::vector<StreamlineField> fields = reader.take_fields();
    for (const StreamlineField& f : fields)
        if (const std::string problem = check_streamline_field(f, scan.fibers, scan.points); !problem.empty())
            throw Error(Errc::invalid_input, tck_path + ": " + problem);
    if (scan.points == 0) scan.min = scan.max = {0, 0, 0};
    if (scan.segments == 0) scan.step_min = 0;
    scan.step_mean = scan.segments ? length_sum / double(scan.segments) : 0.0;
    scan.step_median = lengths.median();

    // The step: the mean over segments for fixed-step data; for variable
    // spacing the header's step_size when the data agrees with it, else the
    // median spacing; --step overrides. Resample when the spacing departs
    // from the chosen step by more than the tolerance.
    const double tol = options.step_tolerance;
    const bool variable = scan.segments > 0 && (scan.step_max > scan.step_mean * (1 + tol) ||
                                                scan.step_min < scan.step_mean * (1 - tol));
    double step = scan.step_mean;
    if (options.step_mm) {
        step = *options.step_mm;
    } else if (variable) {
        step = scan.header_step && std::fabs(*scan.header_step - scan.step_median) <= 0.05 * *scan.header_step
                   ? *scan.header_step
                   : scan.step_median;
    }
    report.resampled = scan.segments > 0 && (variable || std::fabs(step - scan.step_mean) > tol * step);
    if (report.resampled && !(step > 0))
        throw Error(Errc::invalid_input, tck_path + ": cannot resample: the measured step is zero");

    // Normalization into the unit cube; the step is what the decoder will
    // use (float, normalized), and resampling uses exactly that length.
    FftHeader& h = report.header;
    h.version = wide ? kFft16Version : kFftVersion;
    h.points_per_block = points_per_block;
    h.fibers = scan.fibers;
    double extent = 0;
    for (int a = 0; a < 3; ++a) {
        h.offset[a] = float(-0.5 * (scan.min[a] + scan.max[a]));
        extent = std::max(extent, scan.max[a] - scan.min[a]);
    }
    // A step longer than the largest side (a diagonal segment) would leave [0, 1): widen.
    if (step >= extent) extent = step * 1.01;
    h.scaling = extent > 0 ? float(extent * (1 + 1e-6)) : 1.0f;  // a hair larger: float offsets stay inside [0,1]
    if (!std::isfinite(h.scaling))
        throw Error(Errc::invalid_input, tck_path + ": coordinates span more than the float range (" +
                                             std::to_string(extent) + " mm)");
    h.step = float(step / h.scaling);
    check_step_resolvable(tck_path, step, extent, h.step);
    step = double(h.step) * double(h.scaling);
    report.step_mm = step;

    // Pass 1b (resampling only): the counts and turning angles change.
    PointFieldResampler point_fields(report.resampled ? &fields : nullptr, fiber_points);
    // Each fiber's fitted tension (formats/fft.md §5), in kTensionQuantum
    // units: fitted once here, reused by pass 2 (2 bytes a fiber). The fit
    // needs the decoder's stretch of each step: resampled input has its step
    // scale tuned on the sample first (with the input's own turns; the cap
    // is tuned again after this pass, at that scale).
    std::vector<std::uint16_t> tensions(report.resampled ? scan.fibers : 0);
    if (options.step_scale && !(*options.step_scale > 0.5 && *options.step_scale < 2))
        throw Error(Errc::invalid_argument, "the step scale must be in (0.5, 2)");
    std::optional<double> step_scale = options.step_scale;
    if (report.resampled && !step_scale)
        step_scale = detail::tune_parameters({sample.fibers(), {}, step}, turns, h, options.search, step, std::nullopt,
                                             std::nullopt)
                         .step_scale;
    const double stretch = step_scale ? decoder_stretch(float(step * *step_scale / h.scaling), h.scaling, step) : 1.0;
    if (report.resampled) {
        reader.rewind();
        turns = detail::TurnStatistics(points_per_block, kSharpBlocks);
        std::size_t f = 0;
        while (reader.next(fiber)) {
            double fiber_length = 0;
            for (std::size_t i = 1; i < fiber.size(); ++i) fiber_length += length(fiber[i - 1], fiber[i]);
            if (!(fiber_length / step < double(max_fiber_points)))
                throw Error(Errc::unsupported, tck_path + ": " + detail::streamline_label(f) + " (" +
                                                   std::to_string(fiber_length) + " mm) needs more than 65535 blocks at a " +
                                                   std::to_string(step) + " mm step");
            const double tension = length_keeping_tension(fiber, step, stretch);
            tensions[f] = std::uint16_t(std::lround(tension / kTensionQuantum));
            const bool short_tail = resample_cubic_keeping_end(fiber, step, tension, resampled);
            fiber_points[f++] = std::uint32_t(resampled.size());
            // The turn towards a kept end is one step per fiber, often a
            // noisy short one: left out of the turn statistics, so the cap
            // (sized for the whole-step turns) stays as fine as before.
            turns.add_fiber(std::span<const Vec3f>(resampled).first(resampled.size() - short_tail));
            for (std::size_t i = 1; i < fiber.size(); ++i)
                scan.off_step_segments += std::fabs(length(fiber[i - 1], fiber[i]) - step) > tol * step;
            if ((f & 1023) == 0) report_progress(options, "resample-scan", reader);
        }
    }

    point_fields.set_resampled_points(fiber_points);
    // Header: the encoder's choices (parameters.cpp), block layout and buffer table.
    scan.min_dot = turns.min_dot();
    if (options.cap_ratio && !(*options.cap_ratio > 0 && *options.cap_ratio <= 2))
        throw Error(Errc::invalid_argument, "the cap ratio must be in (0, 2]");
    std::optional<float> fixed_ratio;
    if (options.cap_ratio) fixed_ratio = float(*options.cap_ratio);
    else if (options.turn_percentile) fixed_ratio = compute_ratio(h.scaling, step, turns.dot_at_percentile(*options.turn_percentile));
    detail::TunedParameters tuned = detail::tune_parameters(
        {sample.fibers(), turns.sharpest_blocks(), report.resampled ? step : 0.0}, turns, h, options.search, step,
        fixed_ratio, step_scale);
    h.ratio = tuned.ratio;
    report.step_scale = tuned.step_scale;
    h.step = float(step * report.step_scale / h.scaling);
    const FiberEncoder encoder = tuned.encoder ? std::move(*tuned.encoder) : FiberEncoder(h, tuned.search);
    report.search = encoder.search();
    std::vector<FiberLutEntry> lut(scan.fibers);
    const std::uint64_t per_buffer = fft_max_blocks_per_buffer(h.block_bytes());
    std::uint64_t blocks = 0, in_buffer = 0;
    for (std::size_t f = 0; f < fiber_points.size(); ++f) {
        const std::uint32_t nb = encoder.block_count(fiber_points[f]);
        if (nb > 0xffff)
            throw Error(Errc::unsupported, tck_path + ": " + detail::streamline_label(f) + " needs more than 65535 blocks");
        if (in_buffer + nb > per_buffer) h.buffer_ends.push_back(blocks), in_buffer = 0;
        if (h.buffer_ends.size() > 254)
            throw Error(Errc::unsupported, tck_path + ": more than 255 GPU buffers of blocks");
        lut[f] = {std::uint32_t(h.buffer_ends.size()) << 16 | nb, std::uint32_t(in_buffer)};
        blocks += nb, in_buffer += nb;
        h.points += fiber_points[f];
    }
    if (blocks > std::numeric_limits<std::uint32_t>::max())
        throw Error(Errc::unsupported, tck_path + ": more than 2^32 - 1 blocks");
    if (blocks > 0) h.buffer_ends.push_back(blocks);
    h.blocks = std::uint32_t(blocks);

    // Pass 2: encode, measure, write.
    const auto out = detail::open_fft_sink(fft_path, options.overwrite, options.zstd, h.direction_bits(),
                                           h.block_bytes(), threads);
    FftChecksumBuilder checksum(h.block_bytes());  // the CSUM trailer chunk (formats/fft-checksum.md)
    {
        const std::span<const std::uint8_t> lut_bytes{reinterpret_cast<const std::uint8_t*>(lut.data()),
                                                      lut.size() * sizeof(FiberLutEntry)};
        out->begin(serialize_fft_header(h), lut_bytes);
        checksum.add_lut(lut_bytes.data(), lut_bytes.size());
    }
    // The per-fiber tables are written: free them (12 bytes per fiber, 62 MB
    // for 5 M fibers) before the block index grows.
    std::vector<FiberLutEntry>().swap(lut);
    std::vector<std::uint32_t>().swap(fiber_points);
    reader.rewind();
    // Batches of whole fibers are read in order, encoded by `threads`
    // workers on contiguous sub-ranges, and written in order.
    // Resampled fibers keep their true end points: one last-step fraction
    // per fiber (the ENDS chunk, formats/fft-ends.md), 2 bytes a fiber.
    FiberEndFractions end_fractions(report.resampled ? scan.fibers : 0, kWholeLastStep);
    struct Work {
        std::vector<std::uint8_t> blocks;
        std::vector<Vec3f> decoded, decoded_exact, resampled, scratch;
        std::vector<PolylinePosition> positions;  // of the resampled points on the input
        ErrorStats error;
        GeometryError geometry;  // both ways against the input polylines
        IndexBuilder index;  // bounds of this worker's blocks (the BIDX chunk)
    };
    std::vector<Work> work(threads);
    IndexBuilder index(h);
    for (Work& w : work) w.index = index;
    std::vector<std::vector<Vec3f>> batch;
    auto encode_range = [&](Work& w, std::size_t begin, std::size_t end, std::uint32_t first_fiber) {
        w.blocks.clear();
        w.index.clear();
        for (std::size_t i = begin; i < end; ++i) {
            const std::vector<Vec3f>& original = batch[i];
            std::span<const Vec3f> points = original;
            const auto f = std::uint32_t(first_fiber + i);
            w.decoded.clear();
            w.decoded_exact.clear();
            if (report.resampled) {
                const bool short_tail = resample_cubic_keeping_end(original, step, tensions[f] * kTensionQuantum, w.resampled,
                                                                   point_fields.active() ? &w.positions : nullptr);
                if (point_fields.active()) point_fields.resample(f, w.positions);
                points = w.resampled;
                end_fractions[f] = detail::encode_keeping_end(encoder, points, short_tail, step, f, w.blocks,
                                                              w.decoded, &w.decoded_exact, w.scratch);
            } else {
                encoder.encode(points, f, w.blocks, &w.decoded, &w.decoded_exact);
            }
            if (options.block_index) w.index.add_fiber(w.decoded);
            for (std::size_t k = 0; k < points.size(); ++k) {
                // The header's error holds for fiblet's float decoders and an exact one alike.
                const double e = length(points[k], w.decoded[k]);
                w.error.add(w.decoded_exact.empty() ? e : std::max(e, length(points[k], w.decoded_exact[k])), f);
            }
            w.geometry.add_fiber(original, w.decoded, f);
        }
    };
    const std::size_t kBatchPoints = std::size_t(threads) << 16;  // ~0.8 MB of points per thread: stays in cache
    std::uint32_t next_fiber = 0;
    for (bool more = true; more;) {
        std::size_t n = 0, points = 0;
        while (points < kBatchPoints) {
            if (batch.size() <= n) batch.emplace_back();
            if (!(more = reader.next(batch[n]))) break;
            points += batch[n++].size();
        }
        if (n == 0) break;
        // Split the batch into contiguous ranges of about equal point counts.
        std::vector<std::size_t> cut{0};
        std::size_t acc = 0;
        for (std::size_t i = 0; i < n && cut.size() < threads; ++i)
            if ((acc += batch[i].size()) * threads >= points * cut.size()) cut.push_back(i + 1);
        if (cut.back() != n) cut.push_back(n);
        std::vector<std::thread> pool;
        for (std::size_t t = 1; t + 1 < cut.size(); ++t)
            pool.emplace_back(encode_range, std::ref(work[t]), cut[t], cut[t + 1], next_fiber);
        encode_range(work[0], cut[0], cut[1], next_fiber);
        for (auto& th : pool) th.join();
        for (std::size_t t = 0; t + 1 < cut.size(); ++t) {
            out->write_blocks(work[t].blocks);
            checksum.add_blocks(work[t].blocks.data(), work[t].blocks.size());
            index.append(work[t].index);
        }
        next_fiber += std::uint32_t(n);
        report_progress(options, "encode", reader);
    }
    for (const Work& w : work) report.error.merge(w.error), report.geometry.merge(w.geometry);
    if (report.resampled) report.error_vs_original = report.geometry.decoded_to_input();
    h.max_error_mm = float(report.error.max_mm());
    h.mean_error_mm = float(report.error.mean_mm());
    const auto final_head = serialize_fft_header(h);
    std::vector<std::uint8_t> trailer;
    {
        const std::uint64_t at = out->logical_size();
        std::vector<TrailerChunk> chunks{make_properties_chunk(reader.properties())};
        if (!fields.empty()) {
            point_fields.finish();
            chunks.push_back(make_streamline_data_chunk(fields));
            std::vector<StreamlineField>().swap(fields);
        }
        if (report.resampled) {
            TrailerChunk c{kResampledTag, std::vector<std::uint8_t>(16)};  // step, curve, 0
            const auto curve = std::uint32_t(detail::kWrittenCurve);
            std::memcpy(c.payload.data(), &step, 8);
            std::memcpy(c.payload.data() + 8, &curve, 4);
            chunks.push_back(std::move(c));
            chunks.push_back(make_fiber_ends_chunk(end_fractions));
            FiberEndFractions().swap(end_fractions);
        }
        // The builder goes as soon as its chunk is made (its codes are larger than the chunk).
        if (options.block_index)
            if (auto bidx = std::exchange(index, IndexBuilder(h)).finish()) chunks.push_back(std::move(*bidx));
        chunks.push_back(checksum.finish(final_head, chunks));  // last: it covers the chunks before it
        trailer = serialize_trailer(chunks, at);
    }
    out->finish(trailer, final_head);
    report.output_bytes = out->stored_size();
    out->commit();
    if (options.progress) options.progress("encode", 1.0);

    report.input_bytes = tractogram_bytes(tck_path);  // a TRX directory: its files
    report.seconds = timer.seconds();
    return report;
}

}  // namespace fiblet
