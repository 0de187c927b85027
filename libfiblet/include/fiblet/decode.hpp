// fiblet — decoding fiblets into points.
//
// Blocks decode independently: two anchors, then one direction byte per
// further point, each turning the running frame by a frame of the file's
// DirectionTable and advancing by one step. Output is world millimetres as a
// contiguous float32 xyz array (TRX layout, usable as a GPU vertex buffer).
//
// Three decoders compute the same points (docs/decode.md):
//   scalar  the reference: one block after the other, one point after the other;
//   lanes   one block per SIMD lane (16 blocks at a time with AVX-512, 8 with
//           AVX2), each decoded sequentially: the same float operations in the
//           same order as the reference, so the points are bit-identical;
//   warp    the GPU scheme on the CPU: SIMD lanes play the 32 lanes of a warp,
//           one block at a time; frames by an inclusive prefix product
//           (Hillis-Steele, log2 32 = 5 passes), positions by a prefix sum of
//           the rotated steps. Reassociated float sums: the points differ from
//           the reference by a few float roundings (bound in docs/decode.md).
// `automatic` picks the fastest decoder this CPU runs (lanes with the widest
// SIMD it has); every decoder exists everywhere, down to plain C++.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <memory>
#include <vector>

#include "fiblet/direction_code.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/fft_format.hpp"

namespace fiblet {

struct DecodeContext;
// The 16-bit table of a version-16 header, null for version 2.
std::shared_ptr<const DirectionTable16> make_direction_table16(const FftHeader& header);

// Per-file constants the decoders need (built once per file).
struct DecodeContext {
    explicit DecodeContext(const FftHeader& header);
    // With the file's ENDS fractions (fiblet/fiber_ends.hpp): what every
    // decoder of a file's fibers uses, so their last points land on the ends.
    explicit DecodeContext(const FftFile& file);
    FftHeader header;
    DirectionTable table;
    std::shared_ptr<const DirectionTable16> table16 = make_direction_table16(header);  // 16-bit files only
    // The table's frames as rows of 16 floats, one 64-byte line per code:
    // component 3 col + row of code k at [16 k + 3 col + row], zero padded.
    // What the SIMD decoders load.
    alignas(64) std::array<float, 256 * 16> frame_rows{};
    // The same for a 16-bit file's table (every u16 code, 4 MiB), null for version 2.
    struct FrameRows16 {
        alignas(64) std::array<float, 65536 * 16> rows;
    };
    std::shared_ptr<const FrameRows16> frame_rows16;
    // Last-step fractions per fiber; null: fibers end where their blocks do.
    // decode_blocks (and everything built on it) applies them; the raw
    // kernels (decode_blocks_scalar, ...) do not.
    std::shared_ptr<const FiberEndFractions> end_fractions;
};

enum class DecoderKind { automatic, scalar, warp, lanes };
// Instruction set a decoder is built for; `best` = the widest this CPU runs.
enum class SimdLevel { best, portable, avx2, avx512 };

struct Decoder {
    DecoderKind kind = DecoderKind::automatic;
    SimdLevel simd = SimdLevel::best;
};

// Names: "auto", "scalar", "warp", "lanes", or a kind with its level:
// "warp-avx512", "lanes-avx2", "lanes-portable", ... Throws
// Error{invalid_argument} on an unknown name.
Decoder parse_decoder(const std::string& name);
// The concrete decoder a choice runs on this CPU (kind and level never
// `automatic`/`best`; scalar is always `portable`). Throws
// Error{unsupported} when the CPU lacks the level asked for.
Decoder resolve_decoder(Decoder decoder);
std::string decoder_name(Decoder decoder);  // of the resolved decoder
// Every concrete decoder this CPU runs, by name; the first is the one
// `auto` picks.
std::vector<std::string> available_decoders();
// Every concrete decoder this build of the library has, whatever the CPU
// (a level the CPU lacks is refused when asked for).
std::vector<std::string> compiled_decoders();

// Number of points held by `count` blocks; throws Error{fft_format} on a
// block whose point count is 0 or above the file's points per block.
std::size_t count_block_points(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count);

// Decodes `count` blocks into the caller's buffer: writes
// count_block_points() points (3 floats each) to `xyz`, in block order, and
// returns that number. Validates the point counts first (Error{fft_format}).
// `threads` splits the blocks into that many contiguous runs decoded in
// parallel (0 = all cores); small inputs use fewer threads.
std::size_t decode_blocks(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count, float* xyz,
                          Decoder decoder = {}, unsigned threads = 1);

// Whether every point any decoder makes of this file's blocks is finite,
// proven from the header and its direction table alone (docs/decode.md,
// "Finite points": the walk's growth bounded by the frames' norms). False
// proves nothing: such a file may still decode to finite points. A
// consumer that must refuse NaN and Inf (a .tck writer) can skip its check
// when it is true.
bool decodes_finite(const FftHeader& header);

// Scalar reference decoder: plain code, the reference every faster decoder
// is tested against. Writes count_block_points() points (3 floats each) to
// `xyz` and returns that number. Block contents must have been validated by
// count_block_points().
std::size_t decode_blocks_scalar(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count,
                                 float* xyz);

// The scalar decoder of 16-bit files (formats/fft16.md); count_block_points
// and the dispatching decoders handle both kinds.
std::size_t decode_blocks_scalar16(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count,
                                   float* xyz);

// Streamlines in the TRX layout: points of fiber i are xyz[3*offsets[i] ..
// 3*offsets[i+1]).
struct Streamlines {
    std::vector<float> xyz;
    std::vector<std::uint64_t> offsets{0};
    std::size_t size() const { return offsets.size() - 1; }
    std::size_t point_count() const { return offsets.back(); }
};

struct DecodeOptions {
    // Blocks read and decoded at a time (bounds memory). 0: for decode_file,
    // 4096 per thread, so that each chunk's output (~3 MB a thread) is reused
    // in cache instead of mapping fresh pages (bench/results.md: 7x faster
    // than 65536); for decode_fibers, which writes into the whole output, at
    // least 65536 (fewer joins of the pool: docs/parallel.md); for
    // decode_fibers_into, the blocks one thread reads and decodes at a time
    // in its one pool job (4096 of 60 points, as many points of larger ones).
    std::size_t chunk_blocks = 0;
    Decoder decoder;                      // automatic: the fastest on this CPU
    unsigned threads = 0;                 // 0 = all cores; order of the output never depends on it
    // decode_file only: call the sink on a thread of its own, in order, while
    // the next chunk is read and decoded (a pipeline: read -> decode -> sink,
    // e.g. format and write a .tck), which counts among `threads` (threads -
    // 1 decode, at least one). The sink must then not need the caller's
    // thread; its exceptions still reach the caller.
    bool overlap_sink = false;
};

// Decodes fibers [begin, end) of a file.
Streamlines decode_fibers(const FftFile& file, std::uint64_t begin, std::uint64_t end, const DecodeOptions& = {});

// Decodes fibers [begin, end) into caller-provided arrays, without extra
// copies (e.g. straight into a mapped GPU vertex buffer): the points go to
// xyz (3 floats each, from xyz[0]) and offsets[i] is the first point of fiber
// begin + i, offsets[end - begin] the number of points; returns that number.
// `offsets` needs end - begin + 1 entries and `xyz` 3 floats per point (for a
// whole file: 3 * header().points): Error{invalid_argument} when too small,
// checked before anything is written past them.
std::uint64_t decode_fibers_into(const FftFile& file, std::uint64_t begin, std::uint64_t end, std::span<float> xyz,
                                 std::span<std::uint64_t> offsets, const DecodeOptions& = {});

// Streams the whole file in fiber order, a chunk of whole fibers at a time
// (bounded memory): `sink(first_fiber, chunk)`. Throws Error{fft_format}
// after the last chunk when the blocks hold other than header().points
// points (a caller writing an output commits it only after this returns).
void decode_file(const FftFile& file, const std::function<void(std::uint64_t, const Streamlines&)>& sink,
                 const DecodeOptions& = {});

}  // namespace fiblet
