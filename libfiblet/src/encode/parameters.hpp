// Internal: the encoder's free choices for a file — the cap ratio of the
// direction code and the step the decoder walks — made from what the scan
// pass learns about the data. The decoder reads both from the header, so
// any choice gives a valid file; these pick the ones that measure best.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "fiblet/compress.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/fft_format.hpp"
#include "fiblet/geometry.hpp"
#include "fiblet/resample.hpp"

namespace fiblet::detail {

// The curve compress resamples variable-step input on (its RSMP chunk):
// lengths kept fiber by fiber.
inline constexpr ResampleCurve kWrittenCurve = ResampleCurve::rounded_keeping_length;
// A fitted tension as compress keeps it from pass 1b to pass 2 (16 bits,
// in kTensionQuantum units), and back.
inline std::uint16_t tension_code(double tension) { return std::uint16_t(std::lround(tension / kTensionQuantum)); }
inline double tension_of(std::uint16_t code) { return code * kTensionQuantum; }

// A fiber's segments in double: length[s] = |d| of d = f[s + 1] - f[s], as
// distance() computes it, and the unit direction u = d * (1 / length[s])
// as the turn statistics compute it (bit for bit; eight at a time with
// AVX2); `positive`: every length is > 0 (so every u is a direction). The
// scan's lengths and turns both start from them.
struct FiberSegments {
    std::vector<double> length, ux, uy, uz;
    bool positive = true;
};
void fiber_segments(std::span<const Vec3f> f, FiberSegments& out);

// The turning angles between consecutive unit segment directions
// (zero-length segments carry no direction and are skipped): a histogram
// of sin^2(angle / 2) in 2^15 bins (0.013 degree resolution at 15
// degrees), the sharpest turn, and copies of the blocks holding the sharpest turns (where
// a small cap costs the most error, and which a sample would miss).
class TurnStatistics {
public:
    TurnStatistics(std::uint32_t points_per_block, std::size_t kept_blocks);
    void add_fiber(std::span<const Vec3f> fiber);
    // The same, given the fiber's segments (fiber_segments): the scan
    // measures them anyway, and this saves a square root per segment.
    void add_fiber(std::span<const Vec3f> fiber, const FiberSegments& segments);
    // Adds the turns another one counted (same block size; its kept blocks
    // offered in its order): a scan split into parts merges them in order.
    void merge(const TurnStatistics& other);
    std::uint64_t count() const { return count_; }
    // Smallest dot product of consecutive unit directions (1 when none).
    double min_dot() const { return min_dot_; }
    // The dot product of the turn at percentile p of all turns (p = 100: the
    // sharpest turn).
    double dot_at_percentile(double p) const;
    // The points of the blocks holding the sharpest turns (one per fiber).
    std::vector<std::vector<Vec3f>> sharpest_blocks() const;

private:
    std::vector<std::uint64_t> bins_;
    std::uint64_t count_ = 0;
    double min_dot_ = 1;
    std::uint32_t points_per_block_;
    std::size_t kept_blocks_;
    std::vector<std::pair<double, std::vector<Vec3f>>> sharpest_;  // (dot, block points), a max-heap on dot
    bool wants(double dot) const;
    template <class SegmentLength>
    void add_turns(std::span<const Vec3f> fiber, SegmentLength segment_length);
    void keep_sharpest(std::span<const Vec3f> fiber, double fiber_max, std::size_t at);
    void keep(double dot, std::vector<Vec3f> block);
};

// A deterministic sample of whole fibers for tuning: every k-th fiber, with
// k doubling whenever the sample outgrows `max_points`.
class FiberSample {
public:
    explicit FiberSample(std::size_t max_points) : max_points_(max_points) {}
    void offer(std::span<const Vec3f> fiber);
    const std::vector<std::vector<Vec3f>>& fibers() const { return fibers_; }
    std::size_t points() const { return points_; }

private:
    std::size_t max_points_, points_ = 0;
    std::uint64_t seen_ = 0, stride_ = 1;
    std::vector<std::vector<Vec3f>> fibers_;
};

// What the tuning encodes: sampled fibers (resampled to `resample_step_mm`
// first when it is > 0, as the encoder will) and the sharpest-turn blocks
// (already at the encoded spacing).
struct TuningSet {
    std::vector<std::vector<Vec3f>> fibers;
    std::vector<std::vector<Vec3f>> sharp_blocks;
    double resample_step_mm = 0;
};

struct SampleError {
    double mean_mm = 0, max_mm = 0;
    double length_change_mm = 0;  // mean |decoded - target polyline length| over the fibers
    double length_drift_mm = 0;   // mean (decoded - target polyline length), signed
    double length_mm = 0;         // mean target polyline length
    // The tuning objective: mean + max / 3. The max alone is too noisy
    // (a few rare turns), the mean alone lets the cap shrink until the
    // sharpest turns blow up; a max of about three times the mean is what
    // a well-sized cap gives on tractography data.
    double objective() const { return mean_mm + max_mm / 3.0; }
};
// The error of encoding the set's fibers and sharp blocks as they are
// (tune_parameters resamples a set with a resample step once, before it
// measures; the step is not read here).
SampleError measure(const TuningSet& set, const FiberEncoder& encoder);

// Blocks whose max error exceeds this multiple of the mean error are
// searched again with the retry beam (SearchOptions): about 0.4 % of the
// blocks of tractography data, the outliers that make the max error.
inline constexpr double kRetryOverMeanError = 2.5;

struct TunedParameters {
    float ratio = 1;
    double step_scale = 1;
    SearchOptions search;  // with the retry threshold set (when the search retries)
    std::optional<FiberEncoder> encoder;  // built for the chosen ratio when tuning ran (saves a table build)
};

// Chooses the cap ratio and the decoder step for a file by encoding the
// tuning set with the file's search options:
// - ratio: caps sized for turn angles between the 99.9th percentile and the
//   sharpest turn (plus the anchor term of compute_ratio); a smaller cap
//   has finer codes (their spacing shrinks as sqrt(ratio)) but reaches a
//   turn sharper than the cap only over several steps;
// - step scale: the decoder walks chords of one fixed length, and a code
//   grid with no exactly straight direction zig-zags, so a path of
//   sampling-length chords falls behind the input by about angle^2 / 2 per
//   step; a slightly longer decoder step makes up for it.
// - retry threshold (when `search` retries and sets none): a multiple of
//   the mean error the first search makes on the sample.
// `fixed_ratio` / `fixed_scale` skip the corresponding search. `header`
// holds everything else (scaling, offset, block size, bits). `keep_lengths`:
// the encoders measured keep fixed-step lengths (with_length_feedback(1, true));
// `max_ratio`: caps larger than this are not tried.
TunedParameters tune_parameters(const TuningSet& set, const TurnStatistics& turns, FftHeader header,
                                const SearchOptions& search, double sampling_step_mm,
                                std::optional<float> fixed_ratio, std::optional<double> fixed_scale,
                                bool keep_lengths = false, float max_ratio = 2.0f);

// Fixed-step input (the targets are the input's own points): whether its
// fibers keep their lengths with the decoder walking `scale` times the
// sampling step (1 unless the user fixed it) and the tail feedback
// (length_feedback.hpp). The tuned scale (x1.0005) makes every fiber that
// much longer, and the sampling step alone leaves the codes' lag; the two
// together keep iFOD1's lengths within the point error, but not where the
// length excess is the across-track scatter of coarse codes along smooth
// fibers (SD_STREAM: docs/encode.md), which then keep the tuned step and
// no feedback. The cap is tuned again at that scale, with the feedback,
// among caps no larger than the tuned one (finer codes; a wider beam holds
// their rare outliers at the sampling step). Adopted when the
// sample's mean length change is below kKeepLengthsShare of its max point
// error; then `tuned` is replaced.
inline constexpr double kKeepLengthsShare = 0.5;
bool keep_fixed_step_lengths(const TuningSet& set, const TurnStatistics& turns, TunedParameters& tuned,
                             FftHeader header, double sampling_step_mm, std::optional<float> fixed_ratio,
                             std::optional<double> fixed_scale);

}  // namespace fiblet::detail
