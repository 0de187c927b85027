#include "fiblet/geometry_error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace fiblet {

namespace {

double distance(Vec3f a, Vec3f b) {
    const double dx = double(a.x) - b.x, dy = double(a.y) - b.y, dz = double(a.z) - b.z;
    return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// A segment of the polyline measured against: its start, direction and the
// inverse squared length, computed once per fiber (no division per query).
struct Segment {
    double ax, ay, az, ux, uy, uz, inv_uu;
};

void segments_of(std::span<const Vec3f> line, std::vector<Segment>& out) {
    out.clear();
    const std::size_t n = line.size() > 1 ? line.size() - 1 : 1;  // a single point: one degenerate segment
    for (std::size_t s = 0; s < n; ++s) {
        const Vec3f a = line[s], b = line[std::min(s + 1, line.size() - 1)];
        const double ux = double(b.x) - a.x, uy = double(b.y) - a.y, uz = double(b.z) - a.z;
        const double uu = ux * ux + uy * uy + uz * uz;
        out.push_back({a.x, a.y, a.z, ux, uy, uz, uu > 0 ? 1.0 / uu : 0.0});
    }
}

// Squared distance from p to a segment (its start when it has no length).
double distance2(const Segment& g, double px, double py, double pz) {
    const double wx = px - g.ax, wy = py - g.ay, wz = pz - g.az;
    double t = (wx * g.ux + wy * g.uy + wz * g.uz) * g.inv_uu;
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    const double dx = wx - t * g.ux, dy = wy - t * g.uy, dz = wz - t * g.uz;
    return dx * dx + dy * dy + dz * dz;
}

// Every point of `from` against the polyline `to`, in order along both, so
// the nearest segment moves forward with the point: the segments within
// reach of the last nearest one are searched (squared distances, one square
// root per point; this runs on every point `compress` writes): two segments
// back, and ahead the segments one step of `from` can cross plus two.
void points_to_polyline(std::span<const Vec3f> from, std::span<const Vec3f> to, ErrorStats& out, std::uint64_t fiber) {
    if (from.empty() || to.empty()) return;
    thread_local std::vector<Segment> segments;
    segments_of(to, segments);
    const std::size_t ahead = 2 + (to.size() + from.size() - 1) / from.size();
    std::size_t hint = 0;
    for (const Vec3f& p : from) {
        const std::size_t lo = hint > 2 ? hint - 2 : 0, hi = std::min(segments.size(), hint + ahead + 1);
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t s = lo; s < hi; ++s) {
            const double d2 = distance2(segments[s], p.x, p.y, p.z);
            if (d2 < best) best = d2, hint = s;
        }
        out.add(std::sqrt(best), fiber);
    }
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
