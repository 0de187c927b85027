// fiblet — decoding fiblets into points.
//
// Blocks decode independently: two anchors, then one direction byte per
// further point, each turning the running frame by a frame of the file's
// DirectionTable and advancing by one step. Output is world millimetres as a
// contiguous float32 xyz array (TRX layout, usable as a GPU vertex buffer).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
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
    FftHeader header;
    DirectionTable table;
    std::shared_ptr<const DirectionTable16> table16 = make_direction_table16(header);  // 16-bit files only
};

// Number of points held by `count` blocks; throws Error{fft_format} on a
// block whose point count is 0 or above the file's points per block.
std::size_t count_block_points(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count);

// Scalar reference decoder: plain code, the reference every faster decoder
// is tested against. Writes count_block_points() points (3 floats each) to
// `xyz` and returns that number. Block contents must have been validated by
// count_block_points().
std::size_t decode_blocks_scalar(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count,
                                 float* xyz);

// The same two for 16-bit files (formats/fft16.md).
std::size_t count_block_points16(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count);
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
    std::size_t chunk_blocks = 1u << 16;  // blocks read and decoded at a time
};

// Decodes fibers [begin, end) of a file.
Streamlines decode_fibers(const FftFile& file, std::uint64_t begin, std::uint64_t end, const DecodeOptions& = {});

// Streams the whole file in fiber order, a chunk of whole fibers at a time
// (bounded memory): `sink(first_fiber, chunk)`.
void decode_file(const FftFile& file, const std::function<void(std::uint64_t, const Streamlines&)>& sink,
                 const DecodeOptions& = {});

}  // namespace fiblet
