// The compression pipeline: .tck/.trk/TRX -> scan -> (resample) -> encode -> .fft.
// Streams the input (two or three passes over it, two batches of ~256 k points
// in memory at a time); the output is written atomically. This file chooses
// the header; the stages run in compress_scan.cpp and compress_encode.cpp,
// on the worker pool, their input read by compress_read.cpp
// (compress_stages.hpp).
#include "fiblet/compress.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numeric>
#include <memory>
#include <span>
#include <utility>

#include "compress/compress_stages.hpp"
#include "encode/direction_bits.hpp"
#include "encode/fiber_end_encoder.hpp"
#include "encode/greedy_blocks.hpp"
#include "encode/parameters.hpp"
#include "core/streamline_label.hpp"
#include "core/thread_count.hpp"
#include "fiblet/block_index.hpp"
#include "container/fft_writer.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fiber_ends.hpp"
#include "fiblet/output_file.hpp"
#include "fiblet/resample.hpp"
#include "fiblet/source_dtypes.hpp"
#include "fiblet/streamline_data_chunk.hpp"
#include "fiblet/streamline_io.hpp"
#include "fiblet/tractogram_format.hpp"
#include "fiblet/tractogram_space.hpp"

namespace fiblet {

namespace {

// A number as printf's %g writes it (std::to_string prints 1e25 in full).
std::string fmt_g(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

struct Timer {
    std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
    double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); }
};

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

// The block layout for a number of direction bits: 16 bits in packed blocks
// (version 17) in a .fft; in fixed-size blocks (version 16) in a .fftz,
// whose block groups are transposed whole, or when asked for.
struct BlockLayout {
    unsigned bits = 8;
    bool packed = false;
    std::uint32_t points_per_block = kDefaultPointsPerBlock;
};

BlockLayout block_layout(unsigned bits, const CompressOptions& options) {
    const bool wide = bits == 16;
    const bool packed = wide && !options.zstd && !options.fixed_blocks16;
    const std::uint32_t points_per_block =
        options.points_per_block ? options.points_per_block
                                 : (packed ? kDefaultPointsPerBlock16Packed
                                           : wide ? kDefaultPointsPerBlock16 : kDefaultPointsPerBlock);
    const std::uint32_t max_points_per_block = wide ? kMaxPointsPerBlock16 : kMaxPointsPerBlock;
    if (points_per_block < 2 || points_per_block > max_points_per_block)
        throw Error(Errc::invalid_argument,
                    "points per block must be in [2, " + std::to_string(max_points_per_block) + "] for " +
                        std::to_string(bits) + "-bit codes" +
                        (wide ? "" : " (16-bit codes allow up to " + std::to_string(kMaxPointsPerBlock16) + ")"));
    return {bits, packed, points_per_block};
}

void set_layout(FftHeader& h, const BlockLayout& layout) {
    h.version = layout.packed ? kFft16PackedVersion : layout.bits == 16 ? kFft16Version : kFftVersion;
    h.points_per_block = layout.points_per_block;
}

std::string micrometres_g(double mm) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g µm", mm * 1e3);
    return buf;
}

// The report's sentence on the bits (DirectionBitsChoice::reason).
std::string bits_reason(const DirectionBitsChoice& c, unsigned bits, bool wide_blocks_asked, std::uint32_t points_per_block) {
    if (wide_blocks_asked)
        return "16 bits: blocks of " + std::to_string(points_per_block) + " points are beyond 8-bit blocks' " +
               std::to_string(kMaxPointsPerBlock);
    if (c.sample_fibers == 0) return bits == 16 ? "16 bits" : c.automatic ? "8 bits: no fiber to measure" : "8 bits";
    const std::string measured = "lengths by up to " + micrometres_g(c.length_change_max_mm) + " for a point error of " +
                                 micrometres_g(c.point_error_max_mm) + " (sample of " + std::to_string(c.sample_fibers) +
                                 " fibers)";
    if (bits == 16) return "16 bits: 8-bit codes would change " + measured;
    return "8 bits: 8-bit codes change " + measured;
}

// The step: the mean over segments for fixed-step data; for variable
// spacing the header's step_size when the data agrees with it, else the
// median spacing, made finer where every fiber keeps its block count
// (block_keeping_step); options.step_mm overrides. `resampled`: whether the
// spacing departs from the chosen step by more than the tolerance.
double choose_step(const SourceScan& scan, std::span<const float> fiber_lengths, const CompressOptions& options,
                   std::uint32_t points_per_block, bool& resampled) {
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
        // Fibers of few points (blocks are fixed-size): a finer step in as many blocks.
        step = detail::block_keeping_step(fiber_lengths, step, points_per_block);
    }
    resampled = scan.segments > 0 && (variable || std::fabs(step - scan.step_mean) > tol * step);
    return step;
}

// Normalization into the unit cube: the header's offset, scaling and step.
// Returns the step the decoder will walk (float, normalized) in mm:
// resampling uses exactly that length.
double normalize(FftHeader& h, const SourceScan& scan, double step, const std::string& path) {
    double extent = 0;
    for (int a = 0; a < 3; ++a) {
        h.offset[a] = float(-0.5 * (scan.min[a] + scan.max[a]));
        extent = std::max(extent, scan.max[a] - scan.min[a]);
    }
    // A step longer than the largest side (a diagonal segment) would leave [0, 1): widen.
    if (step >= extent) extent = step * 1.01;
    h.scaling = extent > 0 ? float(extent * (1 + 1e-6)) : 1.0f;  // a hair larger: float offsets stay inside [0,1]
    if (!std::isfinite(h.scaling))
        throw Error(Errc::invalid_input,
                    path + ": coordinates span more than the float range (" + std::to_string(extent) + " mm)");
    h.step = float(step / h.scaling);
    check_step_resolvable(path, step, extent, h.step);
    return double(h.step) * double(h.scaling);
}

// The fiber table (LUT) and the header's counts: each fiber's blocks at
// the encoder's block size (plan_fiber_table, container/fft_writer.hpp).
std::vector<FiberLutEntry> plan_blocks(FftHeader& h, const std::vector<std::uint32_t>& fiber_points,
                                       const FiberEncoder& encoder, const std::string& path) {
    h.points += std::accumulate(fiber_points.begin(), fiber_points.end(), std::uint64_t{0});
    return detail::plan_fiber_table(h, fiber_points.size(), [&](std::size_t f) {
        const std::uint32_t blocks = encoder.block_count(fiber_points[f]);
        if (blocks > 0xffff)
            throw Error(Errc::unsupported, path + ": " + detail::streamline_label(f) + " needs more than 65535 blocks");
        return detail::FiberBlocks{blocks, fiber_points[f]};
    }, path);
}

// One compress run, stage by stage: compress_file calls them in order. The
// state passes from stage to stage in these members; each stage says what
// it reads and what it sets.
class CompressJob {
public:
    CompressJob(const std::string& input, const std::string& output, const CompressOptions& options);
    void scan();           // pass 1 (compress_scan.cpp), the data fields' checks
    void choose_step();    // the step (and whether to resample), the header's normalisation
    void resample_scan();  // pass 1b, resampled input only: tensions, counts, turns
    void tune();           // cap, decoder step, encoder; the bits where they are to choose
    void encode();         // pass 2 (compress_encode.cpp): header, fiber table, blocks, errors
    void finish();         // block index, trailer chunks, the header's errors, commit
    CompressReport report;

private:
    static constexpr std::size_t kSharpBlocks = 32;  // blocks of the sharpest turns kept for tuning
    FiberEncoder tuned_encoder();

    const std::string& input_;
    const std::string& output_;
    const CompressOptions& options_;
    const bool choose_bits_;        // unset bits: 8 unless the sample says otherwise after tuning
    const bool wide_blocks_asked_;  // ... or the block size asks for 16-bit blocks
    BlockLayout layout_;
    unsigned threads_ = 1;
    std::size_t max_fiber_points_ = 0;
    std::unique_ptr<StreamlineSource> source_;
    std::vector<std::pair<std::string, std::string>> properties_;
    std::optional<detail::ScanStageResult> scanned_;
    std::vector<StreamlineField> fields_;
    double step_ = 0;
    std::optional<detail::PointFieldResampler> point_fields_;
    std::vector<std::uint16_t> tensions_;
    std::optional<double> step_scale_;
    double stretch_ = 1;
    std::optional<float> fixed_ratio_;
    std::optional<detail::TuningSet> tuning_set_;
    std::optional<FiberEncoder> encoder_;
    std::optional<detail::FftWriter> out_;
    FiberEndFractions end_fractions_;
    std::optional<IndexBuilder> index_;
};

// The options' checks, before any work; the source opened.
CompressJob::CompressJob(const std::string& input, const std::string& output, const CompressOptions& options)
    : input_(input), output_(output), options_(options), choose_bits_(!options.direction_bits),
      wide_blocks_asked_(choose_bits_ && options.points_per_block > kMaxPointsPerBlock),
      layout_(block_layout(options.direction_bits.value_or(wide_blocks_asked_ ? 16 : 8), options)) {
    if (options.step_mm && !(std::isfinite(*options.step_mm) && *options.step_mm > 0))
        throw Error(Errc::invalid_argument, "the step must be a positive number of millimetres");
    threads_ = detail::resolve_threads(options.threads);
    report.simd = detail::simd_level_name(detail::simd_level());  // a bad FIBLET_SIMD: refused before any work
    // The longest streamline a file can hold bounds the one in memory too
    // (either layout's while the bits are still to choose).
    max_fiber_points_ = std::size_t{0xffff} * (choose_bits_ ? std::max(layout_.points_per_block,
                                                                         block_layout(16, options).points_per_block)
                                                            : layout_.points_per_block);
    source_ = open_streamline_source(input, {.allow_count_mismatch = options.allow_count_mismatch,
                                             .max_points = max_fiber_points_,
                                             .max_memory = options.max_memory ? options.max_memory : default_memory_budget()});
    properties_ = source_->properties();
    if (options.reference_space) {
        if (space_from_properties(properties_, input))
            throw Error(Errc::invalid_argument, input + " carries its own space (a .trk or TRX header): a reference "
                                                        "image is for sources without one (.tck)");
        add_space_properties(properties_, *options.reference_space);
    }
    report.scan.header_step = source_->step_size();
    AtomicOutputFile::check_destination(output, options.overwrite);  // before the passes, not after
}

// Pass 1: counts, bounding box, spacing, turning angles, the tuning and
// bits samples (the bits on a larger sample than the tuning's:
// direction_bits.hpp); then the data fields against the counts.
void CompressJob::scan() {
    SourceScan& scan = report.scan;
    const std::size_t bits_sample_points =
        choose_bits_ && !wide_blocks_asked_ ? std::max(options_.tuning_points, detail::kBitsSamplePoints) : 0;
    scanned_.emplace(detail::scan_stage(*source_, scan, layout_.points_per_block, kSharpBlocks, options_.tuning_points,
                                        bits_sample_points, threads_, options_, report.timings));
    fields_ = source_->take_fields();
    for (const StreamlineField& f : fields_)
        if (const std::string problem = check_streamline_field(f, scan.fibers, scan.points); !problem.empty())
            throw Error(Errc::invalid_input, input_ + ": " + problem);
    if (scan.points == 0) scan.min = scan.max = {0, 0, 0};
    if (scan.segments == 0) scan.step_min = 0;
    scan.step_mean = scan.segments ? scanned_->length_sum / double(scan.segments) : 0.0;
    scan.step_median = scanned_->lengths.median();
}

void CompressJob::choose_step() {
    step_ = fiblet::choose_step(report.scan, scanned_->fiber_lengths, options_, layout_.points_per_block, report.resampled);
    std::vector<float>().swap(scanned_->fiber_lengths);
    if (report.resampled && !(step_ > 0))
        throw Error(Errc::invalid_input, input_ + ": cannot resample: the measured step is zero");
    FftHeader& h = report.header;
    set_layout(h, layout_);
    h.fibers = report.scan.fibers;
    step_ = normalize(h, report.scan, step_, input_);
    report.step_mm = step_;
}

// Pass 1b (resampled input): each fiber's fitted tension (formats/fft.md
// §5) in kTensionQuantum units, fitted once and reused by pass 2 (2 bytes a
// fiber), and the resampled counts and turns. The fit needs the decoder's
// stretch of each step: resampled input has its step scale tuned on the
// sample first (with the input's own turns; the cap is tuned again after
// pass 1b, at that scale).
void CompressJob::resample_scan() {
    point_fields_.emplace(report.resampled ? &fields_ : nullptr, scanned_->fiber_points);
    tensions_.assign(report.resampled ? report.scan.fibers : 0, 0);
    if (options_.step_scale && !(*options_.step_scale > 0.5 && *options_.step_scale < 2))
        throw Error(Errc::invalid_argument, "the step scale must be in (0.5, 2)");
    step_scale_ = options_.step_scale;
    FftHeader& h = report.header;
    if (report.resampled && !step_scale_) {
        const detail::StageClock clock(report.timings.tune);
        step_scale_ = detail::tune_parameters({scanned_->sample.fibers(), {}, step_}, scanned_->turns, h, options_.search,
                                              step_, std::nullopt, std::nullopt)
                          .step_scale;
    }
    stretch_ = step_scale_ ? decoder_stretch(float(step_ * *step_scale_ / h.scaling), h.scaling, step_) : 1.0;
    if (report.resampled)
        detail::resample_scan_stage(*source_, {step_, stretch_}, options_.step_tolerance, max_fiber_points_, report.scan,
                                    scanned_->fiber_points, tensions_, scanned_->turns, layout_.points_per_block,
                                    kSharpBlocks, threads_, options_, report.timings);
    // A few input points can resample to millions, each with its values:
    // their arrays, and the DATA chunk made of them at the end, are sized
    // against the budget before they exist.
    const std::uint64_t budget = options_.max_memory ? options_.max_memory : default_memory_budget();
    if (const double need = 2 * point_fields_->bytes_for(scanned_->fiber_points); need > double(budget))
        throw Error(Errc::unsupported,
                    input_ + ": the per-point arrays of the resampled streamlines would take " +
                        std::to_string(std::uint64_t(std::min(need / 1048576, 1e18))) + " MiB, more than the memory budget of " +
                        std::to_string(budget >> 20) + " MiB",
                    Remedy::max_memory);
    point_fields_->set_resampled_points(scanned_->fiber_points);
}

// The cap, the decoder step and the encoder for the header's bits
// (parameters.cpp). Resampled fibers keep their length across blocks
// (length_feedback.hpp); fixed-step fibers where the sampling step and the
// tail feedback do it (parameters.hpp, keep_fixed_step_lengths), their
// block tails only.
FiberEncoder CompressJob::tuned_encoder() {
    FftHeader& h = report.header;
    const detail::StageClock clock(report.timings.tune);
    detail::TunedParameters tuned =
        detail::tune_parameters(*tuning_set_, scanned_->turns, h, options_.search, step_, fixed_ratio_, step_scale_);
    const bool keep_lengths = !report.resampled && detail::keep_fixed_step_lengths(*tuning_set_, scanned_->turns, tuned, h,
                                                                                  step_, fixed_ratio_, step_scale_);
    h.ratio = tuned.ratio;
    report.step_scale = tuned.step_scale;
    report.lengths_kept = keep_lengths;
    h.step = float(step_ * report.step_scale / h.scaling);
    return (tuned.encoder ? std::move(*tuned.encoder) : FiberEncoder(h, tuned.search))
        .with_length_feedback(report.resampled ? float(decoder_stretch(h.step, h.scaling, step_))
                              : keep_lengths   ? 1.0f
                                               : 0.0f,
                              !report.resampled);
}

// Bits to choose: what 8-bit codes do to the sample's lengths; 16 bits when
// they would not keep them (direction_bits.hpp), or when a fiber needs more
// 8-bit blocks than a file holds. The 16-bit encoder is tuned as for
// --bits 16 on the same sample (fixed-step input: the same bytes);
// resampled input keeps the step and the decoder step pass 1b fitted its
// tensions to.
void CompressJob::tune() {
    FftHeader& h = report.header;
    report.scan.min_dot = scanned_->turns.min_dot();
    if (options_.cap_ratio && !(*options_.cap_ratio > 0 && *options_.cap_ratio <= 2))
        throw Error(Errc::invalid_argument, "the cap ratio must be in (0, 2]");
    if (options_.cap_ratio) fixed_ratio_ = float(*options_.cap_ratio);
    else if (options_.turn_percentile)
        fixed_ratio_ = compute_ratio(h.scaling, step_, scanned_->turns.dot_at_percentile(*options_.turn_percentile));
    tuning_set_.emplace(
        detail::TuningSet{scanned_->sample.fibers(), scanned_->turns.sharpest_blocks(), report.resampled ? step_ : 0.0});
    encoder_.emplace(tuned_encoder());
    std::optional<std::uint32_t> too_long;  // points of a fiber 8-bit blocks cannot hold
    if (choose_bits_ && h.direction_bits() == 8) {
        {
            const detail::StageClock clock(report.timings.tune);
            report.bits = detail::measure_sample_lengths(scanned_->bits_sample.fibers(), *encoder_,
                                                          {report.resampled ? step_ : 0.0, stretch_}, threads_);
        }
        const std::vector<std::uint32_t>& points = scanned_->fiber_points;
        const std::uint32_t longest = points.empty() ? 0 : *std::max_element(points.begin(), points.end());
        if (encoder_->block_count(longest) > 0xffff) too_long = longest;
        if (too_long || !detail::eight_bits_keep_lengths(report.bits)) {
            layout_ = block_layout(16, options_);
            set_layout(h, layout_);
            encoder_.emplace(tuned_encoder());
        }
    }
    report.bits.automatic = choose_bits_;
    report.bits.reason = too_long ? "16 bits: a fiber of " + std::to_string(*too_long) +
                                        " points needs more than 65535 blocks of 8-bit codes"
                                  : bits_reason(report.bits, h.direction_bits(), wide_blocks_asked_, layout_.points_per_block);
    report.search = encoder_->search();
}

// Pass 2: the header and the fiber table, then the blocks, encoded and
// measured (compress_encode.cpp).
void CompressJob::encode() {
    FftHeader& h = report.header;  // plan_blocks sets the block count
    std::vector<FiberLutEntry> lut = plan_blocks(h, scanned_->fiber_points, *encoder_, input_);
    out_.emplace(output_, options_.overwrite, options_.zstd, h, lut, threads_);
    // The per-fiber tables are written: free them (12 bytes per fiber, 62 MB
    // for 5 M fibers) before the block index grows.
    std::vector<FiberLutEntry>().swap(lut);
    std::vector<std::uint32_t>().swap(scanned_->fiber_points);
    // Resampled fibers keep their true end points: one last-step fraction
    // per fiber (the ENDS chunk, formats/fft-ends.md), 2 bytes a fiber.
    end_fractions_ = FiberEndFractions(report.resampled ? report.scan.fibers : 0, kWholeLastStep);
    index_.emplace(h, options_.index_format);
    const detail::EncodeStageInputs in{.encoder = *encoder_,
                                       .step = report.resampled ? step_ : 0.0,
                                       .point_fields = &*point_fields_,
                                       .end_fractions = &end_fractions_,
                                       .tensions = &tensions_,
                                       .block_index = options_.block_index,
                                       .threads = threads_};
    detail::EncodeStageResult r = detail::encode_stage(*source_, in, *out_, *index_, options_);
    report.error = std::move(r.error);
    report.geometry = std::move(r.geometry);
    report.timings += r.timings;
    // The input's points are finite: a distance that is not finite comes from a
    // decoded point, which a float walk can overflow near the float range.
    const GeometryError& g = report.geometry;
    if (!std::isfinite(g.decoded_to_input().mean_mm()) || !std::isfinite(g.input_to_decoded().mean_mm()))
        throw Error(Errc::invalid_input, input_ + ": coordinates too near the float range (3.4e38 mm) for a float "
                                                  "decoder: decoded points would not be finite");
}

void CompressJob::finish() {
    FftHeader& h = report.header;
    // The block index's chunk first: its builder's codes are larger than the chunk.
    std::optional<TrailerChunk> index_chunk;
    if (options_.block_index) {
        const detail::StageClock clock(report.timings.index);
        index_chunk = std::exchange(*index_, IndexBuilder()).finish();
    }
    const detail::StageClock clock(report.timings.write);  // the trailer and the commit
    if (report.resampled) report.error_vs_original = report.geometry.decoded_to_input();
    h.max_error_mm = float(report.error.max_mm());
    h.mean_error_mm = float(report.error.mean_mm());
    if (report.resampled)  // float per-point arrays are interpolated, stored as float32: their source dtype in PROP
        for (const StreamlineField& f : fields_)
            if (f.scope() == FieldScope::point && is_float_type(f.type) && f.type != FieldType::float32)
                add_source_dtype_property(properties_, f.name, f.type);
    std::vector<TrailerChunk> chunks{make_properties_chunk(properties_)};
    if (!fields_.empty()) {
        point_fields_->finish();
        chunks.push_back(make_streamline_data_chunk(fields_));
        std::vector<StreamlineField>().swap(fields_);
    }
    if (report.resampled) {
        TrailerChunk c{kResampledTag, std::vector<std::uint8_t>(16)};  // step, curve, 0
        const auto curve = std::uint32_t(detail::kWrittenCurve);
        std::memcpy(c.payload.data(), &step_, 8);
        std::memcpy(c.payload.data() + 8, &curve, 4);
        chunks.push_back(std::move(c));
        chunks.push_back(make_fiber_ends_chunk(end_fractions_));
        FiberEndFractions().swap(end_fractions_);
    }
    if (index_chunk) chunks.push_back(std::move(*index_chunk));
    report.output_bytes = out_->finish(h, std::move(chunks));
    out_->commit();
}

}  // namespace

CompressReport compress_file(const std::string& input_path, const std::string& fft_path, const CompressOptions& options) {
    const Timer timer;
    if (options.direction_bits && *options.direction_bits != 8 && *options.direction_bits != 16)
        throw Error(Errc::invalid_argument, "direction bits must be 8 or 16");
    CompressJob job(input_path, fft_path, options);
    job.scan();
    job.choose_step();
    job.resample_scan();
    job.tune();
    job.encode();
    job.finish();
    if (options.progress) options.progress("encode", 1.0);
    CompressReport& report = job.report;
    report.input_bytes = tractogram_bytes(input_path);  // a TRX directory: its files
    report.seconds = timer.seconds();
    return std::move(report);
}

}  // namespace fiblet
