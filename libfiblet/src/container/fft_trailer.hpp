// Internal: the fiblet trailer of a .fft file (formats/fft.md §6): finding
// its chunks, and validating every field of every chunk fiblet knows.
//
// One rule makes the checksums impossible to switch off by damage: a file
// with any byte after its last block is fiblet-written, and its trailer must
// then parse completely and end with a CSUM chunk. Anything else (a damaged
// footer or chunk size, a CSUM tag turned into another tag, a truncated or
// extended file) is an integrity failure (Error{checksum}), never a silent
// fall back to "no checksum". Files of the official encoder end with their
// last block and are unaffected.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fiblet/fft_format.hpp"
#include "fiblet/fiber_ends.hpp"
#include "fiblet/resample.hpp"
#include "fiblet/streamline_field.hpp"

namespace fiblet::detail {

// Reads logical bytes [offset, offset + size) of the file.
using ReadAt = std::function<void(std::uint8_t* out, std::uint64_t size, std::uint64_t offset)>;

struct TrailerChunks {
    std::vector<TrailerChunk> chunks;       // in file order (large unknown chunks: payload not loaded)
    std::uint64_t checksum_chunk_at = 0;    // file offset of the CSUM chunk (the last one)
    std::uint64_t hash_before_checksum = 0; // XXH64 of the chunks before it, as stored (CSUM's trailerHash)
};

// The chunks after the last block (`blocks_end`) of a file of `logical_size`
// bytes; empty when nothing follows the blocks. Throws Error{checksum}
// naming `name` when the bytes after the blocks are not a complete fiblet
// trailer ending with CSUM.
TrailerChunks read_trailer_chunks(const ReadAt& read_at, std::uint64_t blocks_end, std::uint64_t logical_size,
                                  std::uint64_t fibers, const std::string& name);

// The values of the chunks fiblet reads, validated: each known chunk at most
// once, every field in range and consistent with the header. Throws
// Error{fft_format} naming `name`. (CSUM is parsed by FftChecksums::parse.)
struct TrailerValues {
    std::vector<std::pair<std::string, std::string>> properties;  // PROP
    std::optional<Resampling> resampling;                         // RSMP
    std::shared_ptr<const FiberEndFractions> end_fractions;       // ENDS
    std::shared_ptr<const std::vector<StreamlineField>> fields;   // DATA
};
TrailerValues validate_trailer_chunks(const std::vector<TrailerChunk>& chunks, const FftHeader& header,
                                      const std::string& name);

}  // namespace fiblet::detail
