// fiblet — compressing a tractogram (.tck, .trk or TRX) into a .fft file (the whole pipeline).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>

#include "fiblet/encode.hpp"
#include "fiblet/error_stats.hpp"
#include "fiblet/fft_format.hpp"
#include "fiblet/geometry_error.hpp"
#include "fiblet/index_format.hpp"
#include "fiblet/tractogram_space.hpp"

namespace fiblet {

// What a first pass over a tractogram (.tck, .trk, TRX) learns about it.
struct SourceScan {
    std::uint64_t fibers = 0, points = 0, segments = 0;
    std::uint64_t empty_fibers = 0, single_point_fibers = 0;
    std::array<double, 3> min{}, max{};  // bounding box, mm
    double min_dot = 1;                  // smallest dot of consecutive unit segment directions
    double step_mean = 0, step_min = 0, step_max = 0, step_median = 0;  // segment lengths, mm
    std::optional<double> header_step;   // "step_size:" of the header
    std::uint64_t off_step_segments = 0; // segments farther than the tolerance from the chosen step
};

// The zstd stage (formats/fftz.md): groups of blocks compressed into
// independent frames plus a seek table.
struct ZstdOptions {
    int level = 1;                       // zstd level: 1 adds ~13 % to a plain compress, 3 ~22 % for 0.8 % fewer bytes (formats/fftz.md)
    std::uint32_t group_blocks = 4096;   // blocks per frame (the unit of random access)
    bool transpose = true;               // store each group's blocks field by field
};

struct CompressOptions {
    std::optional<double> step_mm;            // overrides the measured step
    std::uint32_t points_per_block = 0;       // 0: 60 for 8-bit codes; 16-bit: 254 (.fft), 126 (.fftz)
    // Encoder choices; the decoder is the same whatever they are (docs/encode.md).
    // 8 (default): version-2 .fft, the official layout and size; 16: version 17
    // (.fft) or 16 (.fftz) (formats/fft16.md); unset (`--bits auto`): 8 unless
    // 8-bit codes would change the sampled fibers' lengths by more than their
    // point error (docs/encode.md, "Why smooth fibers need 16 bits").
    std::optional<unsigned> direction_bits = 8u;
    bool fixed_blocks16 = false;              // 16-bit codes in version 16's fixed-size blocks in a .fft too
    SearchOptions search = search_for_effort(kDefaultEffort);  // code search (see search_for_effort)
    std::optional<double> cap_ratio;          // cap ratio; default: tuned on a sample
    std::optional<double> turn_percentile;    // or: a cap that holds this percentile of the turning angles
    std::optional<double> step_scale;         // decoder step / sampling step; default: tuned on a sample
    std::size_t tuning_points = 1u << 14;     // points in the tuning sample (8k to 32k choose alike)
    std::optional<ZstdOptions> zstd;          // write the seekable zstd container instead of a plain file
    bool block_index = true;                  // write the BIDX chunk (formats/fft-index.md; under 1 % of the file)
    // Its version: a box per 8 blocks (default: loads in a few ms) or a box
    // per block (fewer candidate blocks for selections, ~20x slower to load).
    BlockIndexFormat index_format = kDefaultBlockIndexFormat;
    double step_tolerance = 0.01;             // relative spacing deviation that triggers resampling
    unsigned threads = 0;                     // encoding threads; 0 = all cores
    bool overwrite = false;
    bool allow_count_mismatch = false;
    // Bytes the run's data may take where a small input can ask for much
    // (a TRX's decompressed data arrays: SourceOptions::max_memory; the
    // per-point arrays of resampled streamlines; the per-streamline tables,
    // ~32 bytes a streamline however few its points); beyond it compress
    // stops before allocating (Error{unsupported}, Remedy::max_memory).
    // 0: default_memory_budget().
    std::uint64_t max_memory = 0;
    // The reference space of a source that carries none (a .tck: tckconvert's
    // and DIPY's reference image, space_of_image), stored in the PROP chunk
    // as a .trk's or TRX's is. Error{invalid_argument} for a source with its own.
    std::optional<TractogramSpace> reference_space;
    // progress(phase, fraction in [0,1]); phases "scan", "resample-scan", "encode".
    std::function<void(const char*, double)> progress;
};

// Why the direction bits are what they are: what 8-bit codes do to the
// lengths of a sample of the fibers (measured when the bits are chosen;
// else zero).
struct DirectionBitsChoice {
    bool automatic = false;              // chosen from the data (CompressOptions::direction_bits unset)
    std::size_t sample_fibers = 0;       // fibers the 8-bit codes were measured on
    double length_change_max_mm = 0;     // their largest |decoded - input length|, float32 or exact decode
    double point_error_max_mm = 0;       // their largest point error, float32 or exact decode (the header's measure)
    std::string reason;                  // one sentence, for the report
};

// Where compress spent its time: seconds in each stage, summed over the
// threads that ran it (the worker pool encodes while the caller reads and
// writes, so the sum can exceed CompressReport::seconds).
struct CompressTimings {
    double read = 0;     // parsing the input, every pass
    double scan = 0;     // pass 1 (and 1b when resampling): bounds, spacing, turns
    double tune = 0;     // the cap, the decoder step and the bits, chosen on samples
    double encode = 0;   // resampling, the code search, the end placement, packing
    double metrics = 0;  // the header's error and the symmetric report
    double index = 0;    // the block index (BIDX chunk)
    double write = 0;    // blocks, checksums, trailer, committing the file

    // Each stage by name, in pipeline order (what --json and Python print).
    std::array<std::pair<const char*, double>, 7> stages() const {
        return {{{"read", read}, {"scan", scan}, {"tune", tune}, {"encode", encode}, {"metrics", metrics},
                 {"index", index}, {"write", write}}};
    }
    double total() const {
        double sum = 0;
        for (const auto& [name, seconds] : stages()) sum += seconds;
        return sum;
    }
    CompressTimings& operator+=(const CompressTimings& o) {
        read += o.read, scan += o.scan, tune += o.tune, encode += o.encode;
        metrics += o.metrics, index += o.index, write += o.write;
        return *this;
    }
};

struct CompressReport {
    SourceScan scan;
    DirectionBitsChoice bits;
    FftHeader header;
    double step_mm = 0;              // sampling step: the spacing of the encoded points
    double step_scale = 1;           // decoder step / sampling step (header step = step_mm * step_scale)
    SearchOptions search;            // the search used (with the retry threshold chosen)
    bool resampled = false;          // the input was resampled to the fixed step
    bool lengths_kept = false;       // fixed-step input: block tails searched again to keep lengths
    ErrorStats error;                // decoded vs the encoded points (resampled ones if resampled)
    ErrorStats error_vs_original;    // decoded vs the original polyline (only if resampled)
    GeometryError geometry;          // decoded vs input polylines, both ways; endpoints, lengths
    std::uint64_t input_bytes = 0, output_bytes = 0;
    double seconds = 0;
    CompressTimings timings;
    std::string simd;  // the code search's SIMD level: avx512, avx2, sse4 or scalar (FIBLET_SIMD forces one)
};

// Half of the memory this process may use: the physical memory, or less
// under `ulimit -v`/`-d` or a cgroup v2 memory.max (src/core/memory_budget.cpp).
std::uint64_t default_memory_budget();

// Compresses `input_path` (a .tck, .trk or TRX: open_streamline_source) into
// `fft_path` (atomically; see AtomicOutputFile). Per-streamline and per-point
// data go to the DATA chunk (formats/fft-data.md); the input header to PROP.
CompressReport compress_file(const std::string& input_path, const std::string& fft_path, const CompressOptions& options);

// The earlier names, from when compress read .tck files only.
using TckScan [[deprecated("use SourceScan")]] = SourceScan;
[[deprecated("use compress_file")]] inline CompressReport compress_tck(const std::string& input_path,
                                                                       const std::string& fft_path,
                                                                       const CompressOptions& options) {
    return compress_file(input_path, fft_path, options);
}

}  // namespace fiblet
