// fiblet — how far a decoded tractogram is from its input, both ways.
//
// Point-to-point errors only see what was encoded: a tail the codec dropped,
// or a fiber that got shorter, never counts. GeometryError measures each
// decoded streamline against its input polyline symmetrically:
//   decoded_to_input   every decoded point -> the input polyline
//   input_to_decoded   every input point -> the decoded polyline
//   (their larger max is a Hausdorff distance between the two polylines)
//   endpoints          per fiber, how far its first and its last point moved
//   length change      per fiber, |decoded length - input length|, mm and %
// One implementation, used by `fiblet compress`, `fiblet stats` and Python.
#pragma once

#include <cstdint>
#include <span>

#include "fiblet/error_stats.hpp"
#include "fiblet/geometry.hpp"

namespace fiblet {

// Max and mean of a per-fiber quantity, with the fiber of the max.
struct FiberMax {
    double max = 0, sum = 0;
    std::uint64_t count = 0, worst_fiber = 0;
    void add(double v, std::uint64_t fiber);
    void merge(const FiberMax& o);
    double mean() const { return count ? sum / double(count) : 0.0; }
};

class GeometryError {
public:
    // Adds one streamline. Distances to a polyline are searched in a window
    // of segments around the nearest one so far (linear time along fibers
    // that follow each other); a result is never below the true distance.
    // `pointwise` (empty, or one value per point, the polylines then having
    // as many points; else Error(invalid_argument)) receives
    // |input[k] - decoded[k]|^2, which the report computes anyway (compress's
    // point errors of a fixed-step input).
    void add_fiber(std::span<const Vec3f> input, std::span<const Vec3f> decoded, std::uint64_t fiber,
                   std::span<double> pointwise = {});
    void merge(const GeometryError& o);

    const ErrorStats& decoded_to_input() const { return decoded_to_input_; }
    const ErrorStats& input_to_decoded() const { return input_to_decoded_; }
    double hausdorff_mm() const;
    std::uint64_t hausdorff_fiber() const;
    const FiberMax& endpoint_mm() const { return endpoint_; }          // start and end of every fiber
    const FiberMax& length_change_mm() const { return length_mm_; }   // |ΔL|
    const FiberMax& length_change_percent() const { return length_pct_; }  // |ΔL| / L, fibers with L > 0
    double mean_length_change_mm() const;  // signed mean of ΔL (negative: shorter)
    // The largest distance among the metrics a --max-error bound covers:
    // Hausdorff, endpoint displacement and length change (all mm).
    double worst_mm() const;

private:
    ErrorStats decoded_to_input_, input_to_decoded_;
    FiberMax endpoint_, length_mm_, length_pct_;
    double signed_length_sum_ = 0;
};

// Length of a polyline (mm, summed in double).
double polyline_length(std::span<const Vec3f> line);

}  // namespace fiblet
