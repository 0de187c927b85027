// Internal: the range-coded stream of per-block grid boxes of a BIDX
// version-3 chunk (formats/fft-index.md §2): each block's box is coded
// against the previous block's, with adaptive binary models, so that a box
// per block costs about 5 bits where a fixed-width code needs 28.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace fiblet::detail {

// A box on the index grid: per axis, the cells lo .. lo + extent.
struct GridBox {
    std::array<std::uint32_t, 3> lo{};
    std::array<std::uint8_t, 3> extent{};
    bool operator==(const GridBox&) const = default;
};

inline constexpr std::uint32_t kMaxBoxExtent = 15;  // extents 0..15 cells
// lo < levels <= 1024: a cell stays above 1/1024 of the range, so that the
// 0.001-cell slack of quantized boxes exceeds the float rounding of
// coordinates (2^-24 of their magnitude).
inline constexpr std::uint32_t kMaxGridLevels = 1u << 10;

// The adaptive models and the previous box: what encoder and decoder
// update identically, block after block.
class BoxModel {
public:
    explicit BoxModel(std::uint32_t levels);
    std::uint32_t levels() const { return levels_; }
    unsigned level_bits() const { return level_bits_; }

protected:
    // Values are coded in unary (a bit "more" per step, with its own
    // probability): the common small values take few of the coder's serial
    // steps, which bound the load time.
    static constexpr std::uint32_t kEscape = 31;  // zigzag deltas 0..30; 31: lo follows in level_bits bits
    static constexpr std::uint32_t kContextExtents = 8;  // extents above 7 share a context
    struct Axis {
        std::uint32_t lo = 0, extent = 0;
        std::uint32_t sign = 3;  // of the last delta: 0 negative, 1 zero, 2 positive, 3 coded whole
        // Contexts: the last delta's sign and extent (and, for deltas, the box's extent).
        std::array<std::array<std::uint16_t, kMaxBoxExtent>, 4 * kContextExtents> extent_steps;
        std::array<std::array<std::uint16_t, kEscape>, 4 * kContextExtents * kContextExtents> delta_steps;
        std::uint16_t* extent_context() { return extent_steps[sign * kContextExtents + capped(extent)].data(); }
        std::uint16_t* delta_context(std::uint32_t e) {
            return delta_steps[(sign * kContextExtents + capped(extent)) * kContextExtents + capped(e)].data();
        }
        static std::uint32_t capped(std::uint32_t e) { return e < kContextExtents ? e : kContextExtents - 1; }
    };
    std::uint16_t bounded_;  // probability that a block has a box
    std::array<Axis, 3> axes_;
    std::uint32_t levels_;
    unsigned level_bits_;
};

class BoxStreamEncoder : BoxModel {
public:
    using BoxModel::BoxModel;
    // The next block's box (nullopt: unbounded); a fiber's first box is
    // coded whole, the others against the previous one.
    void add(const std::optional<GridBox>& box, bool first_of_fiber);
    std::vector<std::uint8_t> finish() const;     // the stream so far, flushed (the encoder stays usable)

private:
    void bit(std::uint16_t& p, unsigned b);
    void unary(std::uint16_t* p, std::uint32_t max, std::uint32_t v);
    void direct(unsigned bits, std::uint32_t v);
    void shift_low();
    std::uint64_t low_ = 0;
    std::uint32_t range_ = 0xffffffffu;
    std::uint8_t cache_ = 0;
    std::uint64_t cache_size_ = 1;
    std::vector<std::uint8_t> out_;
};

// Decodes a box per block (nullopt: unbounded), first_of_fiber[b] telling
// where fibers start. A malformed stream (a box off the grid, a stream shorter or
// longer than its boxes) gives an error message, which the chunk's users
// report as an fft_format error.
struct DecodedBoxes {
    std::vector<std::optional<GridBox>> boxes;
    std::string error;  // empty when well-formed
};
DecodedBoxes decode_box_stream(const std::uint8_t* data, std::size_t size,
                               const std::vector<bool>& first_of_fiber, std::uint32_t levels);

}  // namespace fiblet::detail
