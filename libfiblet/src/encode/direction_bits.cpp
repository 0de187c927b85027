#include "encode/direction_bits.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "encode/fiber_end_encoder.hpp"
#include "encode/parameters.hpp"
#include "fiblet/geometry_error.hpp"
#include "fiblet/parallel.hpp"
#include "fiblet/resample.hpp"

namespace fiblet::detail {

DirectionBitsChoice measure_sample_lengths(std::span<const std::vector<Vec3f>> fibers, const FiberEncoder& encoder,
                                           SampleResampling resampling, unsigned threads) {
    struct Measured {
        double length_change = 0, error = 0;
        bool counted = false;
    };
    std::vector<Measured> per_fiber(fibers.size());
    // One fiber a task; maxima do not depend on the order they are taken in.
    parallel_for(fibers.size(), threads, [&](std::size_t i) {
        const std::vector<Vec3f>& original = fibers[i];
        if (original.size() < 2) return;
        std::vector<std::uint8_t> blocks;
        std::vector<Vec3f> resampled, decoded, decoded_exact, scratch;
        std::span<const Vec3f> points = original;
        const double input_length = polyline_length(original);
        if (resampling.step_mm > 0) {
            // As pass 1b fits the tension (quantized as the file stores it) and pass 2 encodes.
            const double tension = tension_of(
                tension_code(length_keeping_tension(original, resampling.step_mm, resampling.stretch, kWrittenCurve)));
            const bool short_tail =
                resample_cubic_keeping_end(original, resampling.step_mm, tension, resampled, nullptr, kWrittenCurve);
            points = resampled;
            encode_keeping_end(encoder, points, short_tail, resampling.step_mm, 0, blocks, decoded, &decoded_exact,
                               scratch, input_length);
        } else {
            encoder.encode(points, 0, blocks, &decoded, &decoded_exact);
        }
        Measured& m = per_fiber[i];
        m.length_change = std::fabs(polyline_length(decoded) - input_length);
        if (!decoded_exact.empty())
            m.length_change = std::max(m.length_change, std::fabs(polyline_length(decoded_exact) - input_length));
        m.error = largest_error(points, decoded, decoded_exact, points.size());
        m.counted = true;
    });
    DirectionBitsChoice out;
    for (const Measured& m : per_fiber) {
        if (!m.counted) continue;
        out.length_change_max_mm = std::max(out.length_change_max_mm, m.length_change);
        out.point_error_max_mm = std::max(out.point_error_max_mm, m.error);
        ++out.sample_fibers;
    }
    return out;
}

bool eight_bits_keep_lengths(const DirectionBitsChoice& m) {
    return !(m.length_change_max_mm > kLengthOverPointError * m.point_error_max_mm);
}

}  // namespace fiblet::detail
