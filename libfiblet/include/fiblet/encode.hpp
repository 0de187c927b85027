// fiblet — encoding streamlines into fiblets.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "fiblet/direction_code.hpp"
#include "fiblet/fft_format.hpp"

namespace fiblet {

// How hard the encoder searches for the codes of a block (the decoder is the
// same whatever is chosen). beam_width 1 is greedy closed-loop aiming; a
// wider beam keeps that many candidate code sequences per step and returns
// the one with the smallest sum of squared point errors over the block.
// A block whose largest error exceeds retry_error_mm is searched again
// with the retry beam, and the better of the two kept (smaller max error):
// the rare blocks at turns sharper than the cap get the wide search, the
// others stay fast.
struct SearchOptions {
    unsigned beam_width = 1;        // 1..64
    unsigned radius = 1;            // candidates per sequence: (2 radius + 1)^2 codes around the aimed one; 1..3
    unsigned retry_beam_width = 0;  // 0: no retry; else 2..64
    unsigned retry_radius = 1;      // 1..3
    double retry_error_mm = 0;      // retry blocks whose max error exceeds this (> 0)
    // Greedy aiming (beam 1, 8-bit codes) judges each code and its 3x3
    // neighbours by their error plus the errors greedy aiming makes at
    // the next `lookahead` points from where they lead; 0: plain greedy aiming.
    unsigned lookahead = 0;  // 0..6
};

// The search of each effort level (0..kMaxEffort), from fast to thorough;
// docs/encode.md lists them with their measured speed and error. The
// retry threshold is set by the compress pipeline from the tuning sample.
inline constexpr int kDefaultEffort = 1;
inline constexpr int kMaxEffort = 4;
SearchOptions search_for_effort(int effort);

// Encodes one fixed-step streamline at a time into blocks, with the file's
// parameters (scaling, offset, ratio, step, points per block, and the
// direction bits through the version) taken from a header. Closed loop:
// each direction is chosen from the *decoded* previous point and frame, so
// quantization errors do not accumulate along a block. Thread-safe (const).
class FiberEncoder {
public:
    explicit FiberEncoder(const FftHeader& header, SearchOptions search = {});

    const FftHeader& header() const { return header_; }
    const SearchOptions& search() const { return search_; }
    std::uint32_t block_count(std::size_t points) const {
        return std::uint32_t((points + header_.points_per_block - 1) / header_.points_per_block);
    }

    // The same encoder walking another step (normalized units); shares the
    // code tables, so trying several steps costs no table builds.
    FiberEncoder with_step(float step) const;
    FiberEncoder with_search(const SearchOptions& search) const;
    // The same encoder keeping each fiber's length across its blocks
    // (encode/length_feedback.hpp): the decoded length is steered towards
    // the targets' polyline length times `stretch` (the decoder's step over
    // the targets' spacing, for resampled input); 0 turns it off (default).
    // `tails_only` (fixed-step input, 8-bit codes): only where the fiber's
    // length error exceeds a share of its point error, and only a block's
    // last codes are searched again, with the block's own search.
    FiberEncoder with_length_feedback(float stretch, bool tails_only = false) const;

    // Appends block_count(fiber.size()) blocks to `out`. When `decoded` is
    // given, the points fiblet's (float32) decoders will produce (world mm)
    // are appended to it; `decoded_exact` gets the points an
    // exact (float64) decoder of the format produces, rounded to float.
    // Where a block's first frame is ill-conditioned the two differ by more
    // than float rounding; the encoder chooses codes that suit both there.
    void encode(std::span<const Vec3f> fiber, std::uint32_t fiber_id, std::vector<std::uint8_t>& out,
                std::vector<Vec3f>* decoded = nullptr, std::vector<Vec3f>* decoded_exact = nullptr) const;
    // The same as encode() of each fiber in turn (ids first_id, first_id + 1,
    // ...), the same bytes, faster: some of the fibers' searches run together.
    void encode_fibers(std::span<const std::span<const Vec3f>> fibers, std::uint32_t first_id, std::vector<std::uint8_t>& out,
                       std::vector<Vec3f>* decoded = nullptr, std::vector<Vec3f>* decoded_exact = nullptr) const;

private:
    struct Tables;
    struct Encoding;  // one fiber's passes (fiber_encoder.cpp)
    FftHeader header_;
    SearchOptions search_;
    float length_stretch_ = 0;
    bool length_tails_only_ = false;
    std::shared_ptr<const Tables> tables_;
    static std::shared_ptr<const Tables> shared_tables(unsigned bits, float ratio, unsigned levels);
};

// Ratio of the direction code for a file: E = scaling / 2^16 (anchor
// quantization), A = atan(2E / (step - 2E)), Ratio = min(2, 1 - cos(acos(minDot) + A)),
// with step in mm and minDot the smallest dot product of consecutive unit
// segment directions (or, for a robust cap, that of a high percentile of
// the turning angles).
float compute_ratio(double scaling_mm, double step_mm, double min_dot);

}  // namespace fiblet
