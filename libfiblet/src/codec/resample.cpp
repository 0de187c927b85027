#include "fiblet/resample.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fiblet {

namespace {
struct V3 {
    double x, y, z;
};
V3 to_v3(Vec3f p) { return {p.x, p.y, p.z}; }
V3 sub(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// Distance from p to the segment [a, b].
double segment_distance(V3 p, V3 a, V3 b) {
    const V3 ab = sub(b, a), ap = sub(p, a);
    const double len2 = dot(ab, ab);
    double t = len2 > 0 ? dot(ap, ab) / len2 : 0.0;
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    const V3 d{ap.x - t * ab.x, ap.y - t * ab.y, ap.z - t * ab.z};
    return std::sqrt(dot(d, d));
}
}  // namespace

void resample_fixed_step(std::span<const Vec3f> in, double step, std::vector<Vec3f>& out,
                         std::vector<PolylinePosition>* positions) {
    out.clear();
    if (positions) positions->clear();
    if (in.empty()) return;
    V3 cur = to_v3(in[0]);
    out.push_back(in[0]);
    if (positions) positions->push_back({0, 0.0});
    // Find, on the segments after the current position, the first point at
    // distance `step` from the current point (a sphere-segment intersection).
    std::size_t seg = 0;  // the current point lies on segment [seg, seg+1]
    const double r2 = step * step;
    while (seg + 1 < in.size()) {
        bool found = false;
        for (std::size_t s = seg; s + 1 < in.size(); ++s) {
            const V3 a = to_v3(in[s]), b = to_v3(in[s + 1]);
            if (dot(sub(b, cur), sub(b, cur)) < r2) continue;  // segment end still inside the sphere
            // Solve |a + t (b - a) - cur|^2 = step^2 for the largest t in [0, 1].
            const V3 d = sub(b, a), f = sub(a, cur);
            const double qa = dot(d, d), qb = 2 * dot(f, d), qc = dot(f, f) - r2;
            if (qa <= 0) continue;
            const double disc = std::max(qb * qb - 4 * qa * qc, 0.0);
            double t = (-qb + std::sqrt(disc)) / (2 * qa);
            t = t < 0 ? 0 : (t > 1 ? 1 : t);
            cur = {a.x + t * d.x, a.y + t * d.y, a.z + t * d.z};
            out.push_back({float(cur.x), float(cur.y), float(cur.z)});
            if (positions) positions->push_back({s, t});
            seg = s;
            found = true;
            break;
        }
        if (!found) break;  // the rest of the streamline is within one step: dropped
    }
}

bool resample_keeping_end(std::span<const Vec3f> in, double step, std::vector<Vec3f>& out,
                          std::vector<PolylinePosition>* positions) {
    resample_fixed_step(in, step, out, positions);
    if (in.size() < 2) return false;
    const V3 tail = sub(to_v3(in.back()), to_v3(out.back()));
    if (!(std::sqrt(dot(tail, tail)) > kKeptTailFraction * step)) return false;
    out.push_back(in.back());
    if (positions) positions->push_back({in.size() - 2, 1.0});
    return true;
}

void interpolate_point_values(std::span<const PolylinePosition> positions, const float* in_values,
                              std::size_t components, float* out_values) {
    for (std::size_t k = 0; k < positions.size(); ++k) {
        const PolylinePosition& p = positions[k];
        const float* a = in_values + p.segment * components;
        const float* b = p.t > 0 ? a + components : a;  // t = 0 on a one-point line: no second point
        for (std::size_t c = 0; c < components; ++c)
            out_values[k * components + c] = float(double(a[c]) + p.t * (double(b[c]) - double(a[c])));
    }
}

double distance_to_polyline_near(Vec3f p, std::span<const Vec3f> line, std::size_t& hint, std::size_t window) {
    if (line.empty()) return std::numeric_limits<double>::infinity();
    const V3 q = to_v3(p);
    if (line.size() == 1) return std::sqrt(dot(sub(q, to_v3(line[0])), sub(q, to_v3(line[0]))));
    const std::size_t segments = line.size() - 1;
    const std::size_t lo = hint > window ? hint - window : 0;
    const std::size_t hi = std::min(segments, hint + window + 1);
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t s = lo; s < hi; ++s) {
        const double d = segment_distance(q, to_v3(line[s]), to_v3(line[s + 1]));
        if (d < best) best = d, hint = s;
    }
    return best;
}

double distance_to_polyline(Vec3f p, std::span<const Vec3f> line) {
    std::size_t hint = 0;
    return distance_to_polyline_near(p, line, hint, line.size());
}

}  // namespace fiblet
