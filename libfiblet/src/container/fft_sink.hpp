// Internal: where the compress pipeline writes a .fft — the plain file, or
// the seekable zstd container (formats/fftz.md). Both are written
// atomically (AtomicOutputFile) and take the same logical .fft bytes.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "fiblet/compress.hpp"

namespace fiblet::detail {

class FftSink {
public:
    virtual ~FftSink() = default;
    // The header (a placeholder of its final size, rewritten by finish) and the fiber LUT.
    virtual void begin(std::span<const std::uint8_t> header, std::span<const std::uint8_t> lut) = 0;
    // Whole blocks, in order.
    virtual void write_blocks(std::span<const std::uint8_t> blocks) = 0;
    // Size of the logical .fft written so far (where the trailer will start).
    virtual std::uint64_t logical_size() const = 0;
    // Appends the trailer (may be empty) and rewrites the header.
    virtual void finish(std::span<const std::uint8_t> trailer, std::span<const std::uint8_t> header) = 0;
    // Bytes on disk.
    virtual std::uint64_t stored_size() const = 0;
    virtual void commit() = 0;
};

// `zstd` set: the .fftz container, groups compressed by up to `threads` threads.
std::unique_ptr<FftSink> open_fft_sink(const std::string& path, bool overwrite, const std::optional<ZstdOptions>& zstd,
                                       unsigned direction_bits, std::uint32_t block_bytes, unsigned threads);

}  // namespace fiblet::detail
