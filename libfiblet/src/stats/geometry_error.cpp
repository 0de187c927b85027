#include "fiblet/geometry_error.hpp"

#include <algorithm>
#include <cmath>

#include "fiblet/resample.hpp"

namespace fiblet {

namespace {

double distance(Vec3f a, Vec3f b) {
    const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Every point of `from` against the polyline `to`, in order along both, so
// the nearest segment moves forward with the point; the window spans the
// segments of `to` that can correspond to one step of `from`, plus slack.
void points_to_polyline(std::span<const Vec3f> from, std::span<const Vec3f> to, ErrorStats& out, std::uint64_t fiber) {
    if (from.empty() || to.empty()) return;
    std::size_t hint = 0;
    const std::size_t window = 4 + 2 * to.size() / from.size();
    for (const Vec3f& p : from) out.add(distance_to_polyline_near(p, to, hint, window), fiber);
}

}  // namespace

void FiberMax::add(double v, std::uint64_t fiber) {
    if (count == 0 || v > max) max = v, worst_fiber = fiber;
    sum += v;
    ++count;
}

void FiberMax::merge(const FiberMax& o) {
    if (o.count == 0) return;
    if (count == 0 || o.max > max) max = o.max, worst_fiber = o.worst_fiber;
    sum += o.sum;
    count += o.count;
}

double polyline_length(std::span<const Vec3f> line) {
    double len = 0;
    for (std::size_t i = 1; i < line.size(); ++i) len += distance(line[i - 1], line[i]);
    return len;
}

void GeometryError::add_fiber(std::span<const Vec3f> input, std::span<const Vec3f> decoded, std::uint64_t fiber) {
    points_to_polyline(decoded, input, decoded_to_input_, fiber);
    points_to_polyline(input, decoded, input_to_decoded_, fiber);
    if (input.empty() || decoded.empty()) return;
    endpoint_.add(distance(input.front(), decoded.front()), fiber);
    endpoint_.add(distance(input.back(), decoded.back()), fiber);
    const double li = polyline_length(input), ld = polyline_length(decoded);
    length_mm_.add(std::fabs(ld - li), fiber);
    signed_length_sum_ += ld - li;
    if (li > 0) length_pct_.add(100.0 * std::fabs(ld - li) / li, fiber);
}

void GeometryError::merge(const GeometryError& o) {
    decoded_to_input_.merge(o.decoded_to_input_);
    input_to_decoded_.merge(o.input_to_decoded_);
    endpoint_.merge(o.endpoint_);
    length_mm_.merge(o.length_mm_);
    length_pct_.merge(o.length_pct_);
    signed_length_sum_ += o.signed_length_sum_;
}

double GeometryError::hausdorff_mm() const { return std::max(decoded_to_input_.max_mm(), input_to_decoded_.max_mm()); }

std::uint64_t GeometryError::hausdorff_fiber() const {
    return decoded_to_input_.max_mm() >= input_to_decoded_.max_mm() ? decoded_to_input_.worst_fiber()
                                                                     : input_to_decoded_.worst_fiber();
}

double GeometryError::mean_length_change_mm() const {
    return length_mm_.count ? signed_length_sum_ / double(length_mm_.count) : 0.0;
}

double GeometryError::worst_mm() const { return std::max({hausdorff_mm(), endpoint_.max, length_mm_.max}); }

}  // namespace fiblet
