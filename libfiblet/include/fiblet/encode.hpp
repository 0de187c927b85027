// fiblet — encoding streamlines into fiblets.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "fiblet/direction_code.hpp"
#include "fiblet/fft_format.hpp"

namespace fiblet {

// Encodes one fixed-step streamline at a time into blocks, with the file's
// parameters (scaling, offset, ratio, step, points per block) taken from a
// header. Closed loop: each direction is chosen from the *decoded* previous
// point and frame, so quantization errors do not accumulate along a block.
// Thread-safe (const).
class FiberEncoder {
public:
    explicit FiberEncoder(const FftHeader& header);

    const FftHeader& header() const { return header_; }
    std::uint32_t block_count(std::size_t points) const {
        return std::uint32_t((points + header_.points_per_block - 1) / header_.points_per_block);
    }

    // Appends block_count(fiber.size()) blocks to `out`. When `decoded` is
    // given, the points a decoder will produce (world mm) are appended to it.
    void encode(std::span<const Vec3f> fiber, std::uint32_t fiber_id, std::vector<std::uint8_t>& out,
                std::vector<Vec3f>* decoded = nullptr) const;

private:
    FftHeader header_;
    DirectionTable table_;
};

// Ratio of the direction code for a file: E = scaling / 2^16 (anchor
// quantization), A = atan(2E / (step - 2E)), Ratio = min(2, 1 - cos(acos(minDot) + A)),
// with step in mm and minDot the smallest dot product of consecutive unit
// segment directions.
float compute_ratio(double scaling_mm, double step_mm, double min_dot);

}  // namespace fiblet
