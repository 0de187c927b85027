#include "fiblet/resample.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fiblet/geometry_error.hpp"

namespace fiblet {

namespace {
struct V3 {
    double x, y, z;
};
V3 to_v3(Vec3f p) { return {p.x, p.y, p.z}; }
V3 sub(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 add(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 mul(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
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

// Pieces per input segment when tracing the cubic: about 16 per step, so the
// pieces' own corner cutting (~(1/16)² of a step's) is far below the codec's
// error; segments much shorter than the step stay straight.
constexpr double kPiecesPerStep = 16;
std::size_t pieces_for(double segment_length, double step, double per_step) {
    const double n = std::ceil(per_step * segment_length / step);
    return std::size_t(std::clamp(n, 1.0, 256.0));
}

// The input's distinct points (repeated points carry no direction), and the
// input index of each.
void distinct_points(std::span<const Vec3f> in, std::vector<V3>& p, std::vector<std::size_t>& index) {
    p.clear(), index.clear();
    for (std::size_t i = 0; i < in.size(); ++i)
        if (p.empty() || dot(sub(to_v3(in[i]), p.back()), sub(to_v3(in[i]), p.back())) > 0)
            p.push_back(to_v3(in[i])), index.push_back(i);
}

double length(V3 a) { return std::sqrt(dot(a, a)); }
V3 lerp(V3 a, V3 b, double w) { return add(a, mul(sub(b, a), w)); }

// Unit-speed tangents at the points of a polyline (Bessel's: the derivative of
// the parabola through each point and its neighbours, parameterised by chord
// length); the end tangents are those of the end parabolas.
void bessel_tangents(const std::vector<V3>& p, std::vector<V3>& m) {
    const std::size_t n = p.size();
    m.assign(n, {0, 0, 0});
    auto chord = [&](std::size_t i) { return length(sub(p[i + 1], p[i])); };
    auto unit_chord = [&](std::size_t i) { return mul(sub(p[i + 1], p[i]), 1.0 / chord(i)); };
    for (std::size_t i = 1; i + 1 < n; ++i) {
        const double a = chord(i - 1), b = chord(i);
        m[i] = mul(add(mul(unit_chord(i - 1), b), mul(unit_chord(i), a)), 1.0 / (a + b));
    }
    m[0] = sub(mul(unit_chord(0), 2.0), m[1]);
    m[n - 1] = sub(mul(unit_chord(n - 2), 2.0), m[n - 2]);
}

// How much of the cubic a segment gets: all of it up to two steps long, where
// chords between its points would cut its corners; none from four steps on,
// where the chords lie on the segment itself except across its ends (a
// straight segment of the user's stays straight).
double curve_weight(double segment_length, double step) {
    return std::clamp(2.0 - 0.5 * segment_length / step, 0.0, 1.0);
}

// The chord walk: from the first point, the first point at distance `step`
// on a later part of the curve, again and again (a sphere-segment
// intersection); the curve comes as consecutive straight pieces, so nothing
// but the output is stored. The tail shorter than one step is dropped.
class ChordWalk {
public:
    ChordWalk(V3 first, double step, std::vector<Vec3f>& out, std::vector<PolylinePosition>* positions)
        : cur_(first), r2_(step * step), out_(out), positions_(positions) {
        out_.clear();
        out_.push_back({float(first.x), float(first.y), float(first.z)});
        if (positions_) positions_->assign(1, {0, 0.0});
    }
    // The next piece [a, b] of the curve (a is the previous piece's b): the
    // part [t0, t1] of input segment `segment`.
    void piece(V3 a, V3 b, std::size_t segment, double t0 = 0, double t1 = 1) {
        const V3 d = sub(b, a);
        const double qa = dot(d, d);
        if (!(qa > 0)) return;
        // While the piece's end is out of the sphere around the current
        // point, the largest t in [0, 1] with |a + t d - cur| = step is next.
        // A straight piece holds at most length / step + 1 such points; more
        // means the arithmetic no longer moves (coordinates whose rounding
        // exceeds the step): stop rather than fill memory.
        const double most = std::sqrt(qa / r2_) + 2;
        for (double n = 0; dot(sub(b, cur_), sub(b, cur_)) >= r2_ && n < most; ++n) {
            const V3 f = sub(a, cur_);
            const double qb = 2 * dot(f, d), qc = dot(f, f) - r2_;
            const double disc = std::max(qb * qb - 4 * qa * qc, 0.0);
            const double t = std::clamp((-qb + std::sqrt(disc)) / (2 * qa), 0.0, 1.0);
            cur_ = add(a, mul(d, t));
            out_.push_back({float(cur_.x), float(cur_.y), float(cur_.z)});
            if (positions_) positions_->push_back({segment, t0 + t * (t1 - t0)});
        }
    }

private:
    V3 cur_;
    double r2_;
    std::vector<Vec3f>& out_;
    std::vector<PolylinePosition>* positions_;
};

// Feeds the walk the input polyline's segments.
void walk_polyline(std::span<const Vec3f> in, ChordWalk& walk) {
    for (std::size_t i = 0; i + 1 < in.size(); ++i) walk.piece(to_v3(in[i]), to_v3(in[i + 1]), i);
}

// One Hermite piece from p0 to p1 (chord length d) with end tangents m0, m1
// (per unit of chord length), fed to the walk as short straight pieces:
// the part [t0, t1] of input segment `segment`.
void walk_hermite(V3 p0, V3 m0, V3 p1, V3 m1, double d, std::size_t pieces, std::size_t segment, double t0,
                  double t1, ChordWalk& walk) {
    V3 from = p0;
    for (std::size_t k = 1; k <= pieces; ++k) {
        const double t = double(k) / double(pieces), t2 = t * t, t3 = t2 * t;
        // p0 + (p1 - p0) h01 + tangent terms (h00 + h01 = 1): from p0, so
        // that coordinates far larger than the curve (1e28 mm) do not add
        // their rounding (1e12 mm) to it.
        const V3 to = k == pieces ? p1
                                  : add(p0, add(add(mul(sub(p1, p0), 3 * t2 - 2 * t3), mul(m0, d * (t3 - 2 * t2 + t))),
                                                mul(m1, d * (t3 - t2))));
        walk.piece(from, to, segment, t0 + (t1 - t0) * double(k - 1) / double(pieces), t0 + (t1 - t0) * t);
        from = to;
    }
}

// Feeds the walk the C¹ cubic (Hermite, Bessel tangents) through the input
// points, as short straight pieces; it passes through every input point.
// `tension` scales every tangent: 0 gives the polyline itself, 1 the Bessel
// cubic, more a rounder curve (directions, hence C¹ joints, are kept).
// Long segments (`rounded`: the rounded-corner curve; else the older one):
//  - older: the tangents lean towards the segment (curve_weight), a
//    Hermite segment whose end tangents are its own direction being the
//    segment; from four steps on the segment is straight, so chords cut its
//    corners whatever the tension;
//  - rounded: the segment is straight but for a Hermite piece of
//    kCornerSteps steps at each end, from the point's tangent to the
//    segment's direction: the corner is rounded at the step's scale, and
//    the tension still lengthens it.
void walk_cubic(std::span<const Vec3f> in, double step, double tension, double pieces_per_step, bool rounded,
                ChordWalk& walk) {
    thread_local std::vector<V3> p, m;
    thread_local std::vector<std::size_t> index;
    distinct_points(in, p, index);
    // Distinct points i and i + 1 end input segment index[i + 1] - 1 (the
    // copies of point i before it have no length).
    auto segment = [&](std::size_t i) { return index[i + 1] - 1; };
    if (p.size() < 3) {
        if (p.size() == 2) walk.piece(p[0], p[1], segment(0));
        return;
    }
    bessel_tangents(p, m);
    const double corner = kCornerSteps * step;
    for (std::size_t i = 0; i + 1 < p.size(); ++i) {
        const double d = length(sub(p[i + 1], p[i]));
        const V3 u = mul(sub(p[i + 1], p[i]), 1.0 / d);
        if (rounded && d > 2 * corner) {
            const V3 a = add(p[i], mul(u, corner)), b = sub(p[i + 1], mul(u, corner)), ut = mul(u, tension);
            const std::size_t pieces = pieces_for(corner, step, pieces_per_step);
            walk_hermite(p[i], mul(m[i], tension), a, ut, corner, pieces, segment(i), 0, corner / d, walk);
            walk.piece(a, b, segment(i), corner / d, 1 - corner / d);
            walk_hermite(b, ut, p[i + 1], mul(m[i + 1], tension), corner, pieces, segment(i), 1 - corner / d, 1, walk);
            continue;
        }
        const double w = rounded ? 1.0 : curve_weight(d, step);
        const V3 m0 = mul(lerp(u, m[i], w), tension), m1 = mul(lerp(u, m[i + 1], w), tension);
        const std::size_t pieces = w > 0 ? pieces_for(d, step, pieces_per_step) : 1;
        walk_hermite(p[i], m0, p[i + 1], m1, d, pieces, segment(i), 0, 1, walk);
    }
}

// The chord walk on the curve of the given tension (the polyline for
// ResampleCurve::polyline), then the input's last point when the tail is kept.
// Returns whether it was appended.
bool resample_on(std::span<const Vec3f> in, double step, ResampleCurve curve, double tension, bool keep_end,
                 double pieces_per_step,
                 std::vector<Vec3f>& out, std::vector<PolylinePosition>* positions) {
    out.clear();
    if (positions) positions->clear();
    if (in.empty()) return false;
    ChordWalk walk(to_v3(in[0]), step, out, positions);
    if (curve == ResampleCurve::polyline) walk_polyline(in, walk);
    else walk_cubic(in, step, tension, pieces_per_step, curve == ResampleCurve::rounded_keeping_length, walk);
    if (!keep_end || in.size() < 2) return false;
    const V3 tail = sub(to_v3(in.back()), to_v3(out.back()));
    if (!(std::sqrt(dot(tail, tail)) > kKeptTailFraction * step)) return false;
    out.push_back(in.back());
    if (positions) positions->push_back({in.size() - 2, 1.0});
    return true;
}

}  // namespace

double length_keeping_tension(std::span<const Vec3f> in, double step, double stretch, ResampleCurve curve) {
    constexpr double kMax = kMaxResampleTension;
    const double target = polyline_length(in), tolerance = kLengthTolerance * step;
    thread_local std::vector<Vec3f> walked;
    // Length of the decoded fiber minus the input's, at tension t (the
    // chords between anchors, two a block, are not stretched: 0.1 % of a
    // step each, left out).
    auto excess = [&](double t) {
        resample_on(in, step, curve, t, true, kPiecesPerStep, walked, nullptr);
        return stretch * polyline_length(walked) - target;
    };
    double best_t = 1, best = excess(1);
    if (!(std::fabs(best) > tolerance)) return best_t;
    // Multiples of the quantum, so that a tension kept in 16 bits is the one
    // fitted (the lengths move by nanometres).
    auto quantized = [](double t) { return std::round(t / kTensionQuantum) * kTensionQuantum; };
    auto consider = [&](double t, double e) {
        if (std::fabs(e) < std::fabs(best)) best = e, best_t = t;
    };
    // Bracket the root: rounder curves are longer, so move away from the
    // Bessel cubic towards the missing length (1.75, 2.5, 4 or 0.5, 0).
    const bool too_short = best < 0;
    double lo = 1, e_lo = best, hi = 1, e_hi = best;
    const double up[] = {1.75, 2.5, kMax}, down[] = {0.5, 0};
    bool bracketed = false;
    for (const double t : too_short ? std::span<const double>(up) : std::span<const double>(down)) {
        const double e = excess(t);
        consider(t, e);
        bracketed = (e < 0) != too_short || e == 0;
        (bracketed == too_short ? hi : lo) = t, (bracketed == too_short ? e_hi : e_lo) = e;
        if (bracketed) break;
    }
    if (!bracketed || !(std::fabs(best) > tolerance)) return quantized(best_t);
    // Regula falsi, Illinois variant (halves the weight of an end kept twice).
    int kept_side = 0;
    for (int i = 0; i < kMaxTensionIterations && std::fabs(best) > tolerance; ++i) {
        const double t = (lo * e_hi - hi * e_lo) / (e_hi - e_lo);
        const double e = excess(t);
        consider(t, e);
        if ((e < 0) == (e_lo < 0)) {
            lo = t, e_lo = e;
            if (kept_side == 1) e_hi *= 0.5;
            kept_side = 1;
        } else {
            hi = t, e_hi = e;
            if (kept_side == -1) e_lo *= 0.5;
            kept_side = -1;
        }
    }
    return quantized(best_t);
}

bool resample_cubic_keeping_end(std::span<const Vec3f> in, double step, double tension, std::vector<Vec3f>& out,
                                std::vector<PolylinePosition>* positions, ResampleCurve curve) {
    return resample_on(in, step, curve, tension, true, kPiecesPerStep, out, positions);
}

namespace {
// The tension `how` resamples on: fitted for the length-keeping curve, else
// Bessel's (1; the polyline walk ignores it).
double tension_for(std::span<const Vec3f> in, const Resampling& how) {
    return keeps_length(how.curve) ? length_keeping_tension(in, how.step_mm, how.stretch, how.curve) : 1.0;
}
}  // namespace

void resample_fixed_step(std::span<const Vec3f> in, double step, std::vector<Vec3f>& out, ResampleCurve curve,
                         std::vector<PolylinePosition>* positions) {
    const Resampling how{.step_mm = step, .curve = curve};
    resample_on(in, step, curve, tension_for(in, how), false, kPiecesPerStep, out, positions);
}

bool resample_keeping_end(std::span<const Vec3f> in, double step, std::vector<Vec3f>& out, ResampleCurve curve,
                          std::vector<PolylinePosition>* positions) {
    const Resampling how{.step_mm = step, .curve = curve};
    return resample_on(in, step, curve, tension_for(in, how), true, kPiecesPerStep, out, positions);
}

void resample_fixed_step(std::span<const Vec3f> in, const Resampling& how, std::vector<Vec3f>& out) {
    resample_on(in, how.step_mm, how.curve, tension_for(in, how), false, kPiecesPerStep, out, nullptr);
}

bool resample_keeping_end(std::span<const Vec3f> in, const Resampling& how, std::vector<Vec3f>& out) {
    return resample_on(in, how.step_mm, how.curve, tension_for(in, how), true, kPiecesPerStep, out, nullptr);
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
