#include "fiblet/geometry_error.hpp"

#include "fiblet/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "core/grow.hpp"
#include "core/points_avx2.hpp"
#include "core/sum_lanes.hpp"
#include "core/vec_math.hpp"
#include "stats/geometry_paths.hpp"

namespace fiblet {

using detail::distance;
using detail::distance2;

namespace {

// The segments of a polyline as columns (start, direction, inverse squared
// length, squared length) in float, computed once per fiber: the window of
// segments a point is measured against is evaluated as one vectorizable
// loop, and the points of a fixed-step pair are read from their own
// polyline's columns. The distances are float arithmetic on the float
// points, eight per AVX2 vector (on AVX-512 machines too): each is within
// a few float ulps of the segment's extent, ~1e-8 mm for 0.1 mm steps,
// against errors of micrometres. The polyline's length, whose change
// between two polylines is micrometres over centimetres, is summed in
// double (the same double arithmetic and order as polyline_length), and so
// are the point errors of fixed-step pairs (the header's).
constexpr std::size_t kLanes = 8;
// Padding segments after the last (the vector loops read up to 10 past it).
constexpr std::size_t kPadding = 16;

#ifdef FIBLET_POINTS_AVX2
#define FIBLET_AVX2 __attribute__((target("avx2"))) inline
#endif

using detail::use_avx2_loops;

// The per-fiber buffers are thread_local and only ever grow (core/grow.hpp).
using detail::grow;

struct Segments {
    std::vector<float> ax, ay, az, ux, uy, uz, inv_uu, uu;
    std::vector<double> len;  // in double, for the length
    std::size_t count = 0;  // segments (the columns hold kPadding padding segments more)
    double length = 0;
    double max_len = 0;  // the longest segment (NaN left out)
};

// Squared distance of p to segment s (its start when it has no length): the
// arithmetic of every distance here.
inline float segment_dist2(const Segments& g, float px, float py, float pz, std::size_t s) {
    const float wx = px - g.ax[s], wy = py - g.ay[s], wz = pz - g.az[s];
    float t = (wx * g.ux[s] + wy * g.uy[s] + wz * g.uz[s]) * g.inv_uu[s];
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    const float dx = wx - t * g.ux[s], dy = wy - t * g.uy[s], dz = wz - t * g.uz[s];
    return dx * dx + dy * dy + dz * dz;
}

// Segment s's columns from its end points a, b (float differences).
inline void set_segment(Segments& g, std::size_t s, Vec3f a, Vec3f b) {
    const float dx = b.x - a.x, dy = b.y - a.y, dz = b.z - a.z, uu = dx * dx + dy * dy + dz * dz;
    g.ax[s] = a.x, g.ay[s] = a.y, g.az[s] = a.z, g.ux[s] = dx, g.uy[s] = dy, g.uz[s] = dz;
    g.uu[s] = uu, g.inv_uu[s] = uu > 0 ? 1.0f / uu : 0.0f;
}

#ifdef FIBLET_POINTS_AVX2
// A polyline's columns as plain pointers: the vector loops keep them in
// registers (their stores may alias a std::vector's, which the compiler
// would otherwise reload after each).
struct ColumnPointers {
    const float *ax, *ay, *az, *ux, *uy, *uz, *inv_uu, *uu;
    explicit ColumnPointers(const Segments& g)
        : ax(g.ax.data()), ay(g.ay.data()), az(g.az.data()), ux(g.ux.data()), uy(g.uy.data()), uz(g.uz.data()),
          inv_uu(g.inv_uu.data()), uu(g.uu.data()) {}
};

FIBLET_AVX2 __m256 norm2_8(__m256 dx, __m256 dy, __m256 dz) {
    return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
}

// segment_dist2 of the points (x, y, z) to segments s .. s + 7: the same
// float operations in the same order (max(0, t) and min(1, t) return t for
// a NaN and keep -0, as the ternaries do; no fused multiply-add:
// -ffp-contract=off).
FIBLET_AVX2 __m256 segment_dist2_avx2(const ColumnPointers& g, __m256 x, __m256 y, __m256 z, std::size_t s) {
    const __m256 ux = _mm256_loadu_ps(g.ux + s), uy = _mm256_loadu_ps(g.uy + s), uz = _mm256_loadu_ps(g.uz + s);
    const __m256 wx = _mm256_sub_ps(x, _mm256_loadu_ps(g.ax + s)), wy = _mm256_sub_ps(y, _mm256_loadu_ps(g.ay + s)),
                 wz = _mm256_sub_ps(z, _mm256_loadu_ps(g.az + s));
    __m256 t = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(wx, ux), _mm256_mul_ps(wy, uy)), _mm256_mul_ps(wz, uz));
    t = _mm256_min_ps(_mm256_set1_ps(1.0f), _mm256_max_ps(_mm256_setzero_ps(), _mm256_mul_ps(t, _mm256_loadu_ps(g.inv_uu + s))));
    const __m256 dx = _mm256_sub_ps(wx, _mm256_mul_ps(t, ux)), dy = _mm256_sub_ps(wy, _mm256_mul_ps(t, uy)),
                 dz = _mm256_sub_ps(wz, _mm256_mul_ps(t, uz));
    return norm2_8(dx, dy, dz);
}

// Squared distances of p to the kLanes segments from `base` into d.
FIBLET_AVX2 void window_avx2(const ColumnPointers& g, float px, float py, float pz, std::size_t base, float* d) {
    _mm256_store_ps(d, segment_dist2_avx2(g, _mm256_set1_ps(px), _mm256_set1_ps(py), _mm256_set1_ps(pz), base));
}

// The columns of segments s .. s + 7 from points s .. s + 8: set_segment's
// float operations (vdivps rounds correctly, as /; the mask keeps +0, as the
// ternary) and the lengths sqrt(uu) in double from the points' double
// differences, as polyline_length's: the same float columns converted to
// double (exact) and subtracted, so no shuffles of their own.
struct ColumnOutputs {  // plain pointers, as ColumnPointers
    float *ax, *ay, *az, *ux, *uy, *uz, *inv_uu, *uu;
    double* len;
    explicit ColumnOutputs(Segments& g)
        : ax(g.ax.data()), ay(g.ay.data()), az(g.az.data()), ux(g.ux.data()), uy(g.uy.data()), uz(g.uz.data()),
          inv_uu(g.inv_uu.data()), uu(g.uu.data()), len(g.len.data()) {}
};

FIBLET_AVX2 void columns8(const Vec3f* p, std::size_t s, const ColumnOutputs& g, __m256d& max_len) {
    __m256 x, y, z, nx, ny, nz;
    detail::xyz8(p + s, x, y, z);
    detail::xyz8(p + s + 1, nx, ny, nz);
    const __m256 dx = _mm256_sub_ps(nx, x), dy = _mm256_sub_ps(ny, y), dz = _mm256_sub_ps(nz, z);
    const __m256 uu = norm2_8(dx, dy, dz);
    _mm256_storeu_ps(g.ax + s, x), _mm256_storeu_ps(g.ay + s, y), _mm256_storeu_ps(g.az + s, z);
    _mm256_storeu_ps(g.ux + s, dx), _mm256_storeu_ps(g.uy + s, dy), _mm256_storeu_ps(g.uz + s, dz);
    _mm256_storeu_ps(g.uu + s, uu);
    _mm256_storeu_ps(g.inv_uu + s,
                     _mm256_and_ps(_mm256_cmp_ps(uu, _mm256_setzero_ps(), _CMP_GT_OQ), _mm256_div_ps(_mm256_set1_ps(1.0f), uu)));
    for (int h = 0; h < 2; ++h) {
        const __m256d l =
            _mm256_sqrt_pd(detail::norm2(detail::double_diff(nx, x, h), detail::double_diff(ny, y, h), detail::double_diff(nz, z, h)));
        _mm256_storeu_pd(g.len + s + 4 * h, l);
        max_len = _mm256_max_pd(l, max_len);  // vmaxpd returns its second operand for a NaN: left out
    }
}

// The columns of every segment of a polyline of at least 9 points, eight at
// a time; the last eight overlap the ones before where the count is not a
// multiple of 8 (the same values written again), so no segment is left for
// the scalar loop.
__attribute__((target("avx2"))) void columns_avx2(const Vec3f* p, std::size_t points, Segments& g) {
    const ColumnOutputs out(g);
    __m256d max_len = _mm256_setzero_pd();
    const std::size_t n = points - 1;
    for (std::size_t s = 0; s + 8 <= n; s += 8) columns8(p, s, out, max_len);
    if (n % 8) columns8(p, n - 8, out, max_len);
    alignas(32) double lanes[4];
    _mm256_store_pd(lanes, max_len);
    for (const double v : lanes) g.max_len = v > g.max_len ? v : g.max_len;
}
#endif

// A non-empty polyline's columns.
void segments_of(std::span<const Vec3f> line, Segments& out) {
    const std::size_t points = line.size(), n = points > 1 ? points - 1 : 1;  // a single point: one degenerate segment
    for (auto* c : {&out.ax, &out.ay, &out.az, &out.ux, &out.uy, &out.uz, &out.inv_uu, &out.uu}) grow(*c, n + kPadding);
    double* len = grow(out.len, n);
    // Segments [0, done) complete from the vector loop.
    std::size_t done = 0;
    out.max_len = 0;
#ifdef FIBLET_POINTS_AVX2
    if (use_avx2_loops() && points >= 9) columns_avx2(line.data(), points, out), done = n;
#endif
    for (std::size_t s = done; s < n; ++s) {
        const Vec3f a = line[s], b = line[std::min(s + 1, points - 1)];
        set_segment(out, s, a, b);
        const double dx = double(b.x) - a.x, dy = double(b.y) - a.y, dz = double(b.z) - a.z;
        len[s] = std::sqrt(dx * dx + dy * dy + dz * dz);
        out.max_len = len[s] > out.max_len ? len[s] : out.max_len;
    }
    // Padding segments, so that a window of up to kLanes segments is always
    // evaluated whole: read, never chosen (the windows end at segment n).
    for (std::size_t p = n; p < n + kPadding; ++p) {
        out.ax[p] = out.ay[p] = out.az[p] = 1e30f;
        out.ux[p] = out.uy[p] = out.uz[p] = out.inv_uu[p] = out.uu[p] = 0.0f;
    }
    out.count = n;
    out.length = points > 1 ? detail::sum_in_four_lanes(len, n) : 0.0;
}

// Fixed-step pairs (as many points on both polylines; point k was encoded
// from to[k]): for each point p = from[k], its squared distances to to[k]'s
// own segments k - 1 and k, and whether one of them is provably the nearest
// segment of the window, without evaluating the others. The window around
// a hint of k - 2, k - 1 or k holds segments k - 4 .. k + 3. Where the
// segments after to[k] up to k + 3 have no component against segment k's
// direction, every point x of segments k + 1 .. k + 3 has (x - to[k]) . u_k
// >= |u_k|, so |x - to[k]| >= |u_k|; likewise back to segment k - 4 from
// segment k - 1. Then those
// segments are at least s - e from p (s: the shorter own segment, e =
// |p - to[k]|), and the nearest own segment at most e: when 2e < s (with
// room for rounding) no other segment can be nearer or tie. Every point of
// a fixed-step fiber whose error is well below half a step and whose turns
// over three steps stay under 90 degrees is proven so: two segments instead
// of the window, the same result bit for bit.
struct OwnSegments {
    std::vector<std::uint8_t> later;    // 1 where the nearer own segment is segment k (the first on a tie)
    std::vector<std::uint8_t> proven;   // it is the window's nearest
    std::vector<float> forward[3];      // vector loops: all bits set where u_s . u_(s + d + 1) >= 0
};

// Point k of own_segments (any k; the edges of the fiber and machines
// without AVX2): its squared distance into nearest[k].
void own_segments_at(const Segments& g, std::span<const Vec3f> from, std::span<const Vec3f> to, std::size_t k,
                     float* nearest, double* pointwise, OwnSegments& out) {
    const std::size_t n = g.count;
    auto dot = [&](std::size_t a, std::size_t b) { return g.ux[a] * g.ux[b] + g.uy[a] * g.uy[b] + g.uz[a] * g.uz[b]; };
    const Vec3f p = from[k];
    const float ex = p.x - to[k].x, ey = p.y - to[k].y, ez = p.z - to[k].z;
    const float e2 = ex * ex + ey * ey + ez * ez, e4 = 4.0f * e2;
    if (pointwise) pointwise[k] = distance2(p, to[k]);
    bool proven = true;
    float before = std::numeric_limits<float>::infinity(), after = before;
    if (k > 0) {  // segment k - 1 and the three before it
        before = segment_dist2(g, p.x, p.y, p.z, k - 1);
        proven = proven && e4 < 0.98f * g.uu[k - 1];
        for (std::size_t j = k >= 4 ? k - 4 : 0; j + 1 < k; ++j) proven = proven && dot(j, k - 1) >= 0;
    }
    if (k < n) {  // segment k and the three after it (the padding's direction is 0)
        after = segment_dist2(g, p.x, p.y, p.z, k);
        proven = proven && e4 < 0.98f * g.uu[k];
        for (std::size_t j = k + 1; j <= k + 3; ++j) proven = proven && dot(j, k) >= 0;
    }
    out.later[k] = after < before;
    nearest[k] = after < before ? after : before;
    out.proven[k] = proven;
}

#ifdef FIBLET_POINTS_AVX2
// smooth_avx2's test of the pairs (s .. s + 7, the segment after each).
FIBLET_AVX2 __m256 smooth_pairs8(const ColumnPointers& g, std::size_t s) {
    const __m256 dot = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(g.ux + s), _mm256_loadu_ps(g.ux + s + 1)),
                                                   _mm256_mul_ps(_mm256_loadu_ps(g.uy + s), _mm256_loadu_ps(g.uy + s + 1))),
                                     _mm256_mul_ps(_mm256_loadu_ps(g.uz + s), _mm256_loadu_ps(g.uz + s + 1)));
    const __m256 cos2 = _mm256_set1_ps(0.7796f);  // cos^2(28°) = 0.77960
    const __m256 bound = _mm256_mul_ps(cos2, _mm256_mul_ps(_mm256_loadu_ps(g.uu + s), _mm256_loadu_ps(g.uu + s + 1)));
    return _mm256_and_ps(_mm256_cmp_ps(dot, _mm256_setzero_ps(), _CMP_GT_OQ),
                         _mm256_cmp_ps(_mm256_mul_ps(dot, dot), bound, _CMP_GT_OQ));
}

// Whether every turn between consecutive segments is under 28 degrees
// (u_s . u_(s+1) > 0 and its square above cos^2(28°) |u_s|^2 |u_(s+1)|^2):
// then segments up to three apart turn by at most 84 degrees, the sum of the
// turns between them, so every forward test holds (their float dot products
// stay positive: rounding moves them by ~1e-6 of |u_a| |u_b|, cos 84° is
// 0.10), and the proof needs no forward masks. Conservative: a zero-length
// segment, or products that overflow or underflow, make a fiber not smooth.
// Most tractography fibers and their decodings are smooth at their step.
__attribute__((target("avx2"))) bool smooth_avx2(const Segments& segments) {
    const std::size_t n = segments.count;  // pairs (s, s + 1) for s + 1 < n, eight at a time, the last eight overlapping
    if (n < 9) return false;
    const ColumnPointers g(segments);
    __m256 all = smooth_pairs8(g, n - 9);
    for (std::size_t s = 0; s + 9 <= n; s += 8) all = _mm256_and_ps(all, smooth_pairs8(g, s));
    return _mm256_movemask_ps(all) == 0xff;
}

// OwnSegments::forward of every segment: each pair of segments up to three
// apart is tested once, not once for each point it proves.
__attribute__((target("avx2"))) void forward_avx2(const Segments& g, OwnSegments& out) {
    const std::size_t n = g.count;
    // Pointers in locals (the stores may alias the vectors, and reloading
    // them went through TLS calls: 16 % of the report).
    float* forward[3];
    for (std::size_t d = 0; d < 3; ++d) forward[d] = grow(out.forward[d], n + 8);
    const float *ux = g.ux.data(), *uy = g.uy.data(), *uz = g.uz.data();
    for (std::size_t s = 0; s < n; s += 8)  // reads up to segment n + 10: padding
        for (std::size_t d = 0; d < 3; ++d) {
            const std::size_t a = s + d + 1;  // u_a . u_s >= 0: not against each other
            const __m256 dot = _mm256_add_ps(
                _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(ux + a), _mm256_loadu_ps(ux + s)),
                              _mm256_mul_ps(_mm256_loadu_ps(uy + a), _mm256_loadu_ps(uy + s))),
                _mm256_mul_ps(_mm256_loadu_ps(uz + a), _mm256_loadu_ps(uz + s)));
            _mm256_storeu_ps(forward[d] + s, _mm256_cmp_ps(dot, _mm256_setzero_ps(), _CMP_GE_OQ));
        }
}

// The eight bytes 0 or 1 of a vector mask (lanes all ones or zero), lane 0
// first: the lanes' top bits packed down to bytes in registers (byte
// patterns from a table indexed by movemask took scalar inserts, ~15 % of
// own_segments_avx2).
FIBLET_AVX2 void store_mask_bytes(__m256 mask, std::uint8_t* out) {
    const __m256i bits = _mm256_srli_epi32(_mm256_castps_si256(mask), 31);
    const __m128i words = _mm_packus_epi32(_mm256_castsi256_si128(bits), _mm256_extracti128_si256(bits, 1));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(out), _mm_packus_epi16(words, words));
}

// The squared distances of points x, y, z from those at gx, gy, gz
// (eight each) in double, as distance2: the header's point errors.
FIBLET_AVX2 void exact_squares(__m256 x, __m256 y, __m256 z, const float* gx, const float* gy, const float* gz,
                               double* out) {
    const __m256 tx = _mm256_loadu_ps(gx), ty = _mm256_loadu_ps(gy), tz = _mm256_loadu_ps(gz);
    for (int h = 0; h < 2; ++h)
        _mm256_storeu_pd(out + 4 * h, detail::norm2(detail::double_diff(x, tx, h), detail::double_diff(y, ty, h),
                                                    detail::double_diff(z, tz, h)));
}

// e4 < 0.98 uu for squared lengths uu .. uu + 7.
FIBLET_AVX2 __m256 within_half_step(__m256 e4, const float* uu8) {
    return _mm256_cmp_ps(e4, _mm256_mul_ps(_mm256_set1_ps(0.98f), _mm256_loadu_ps(uu8)), _CMP_LT_OQ);
}

// own_segments_at for points k .. k + 7 (4 <= k, k + 8 <= n), the points
// read from both polylines' columns: the same distances bit for bit, the
// same proof (kSmooth: `to` is smooth_avx2, its forward tests all hold).
template <bool kSmooth>
FIBLET_AVX2 void own_segments8(const ColumnPointers& g, const ColumnPointers& p, const float* const forward[3],
                               std::size_t k, float* nearest, double* pointwise, std::uint8_t* proven,
                               std::uint8_t* later_out) {
    const __m256 x = _mm256_loadu_ps(p.ax + k), y = _mm256_loadu_ps(p.ay + k), z = _mm256_loadu_ps(p.az + k);
    const __m256 e2 = norm2_8(_mm256_sub_ps(x, _mm256_loadu_ps(g.ax + k)), _mm256_sub_ps(y, _mm256_loadu_ps(g.ay + k)),
                              _mm256_sub_ps(z, _mm256_loadu_ps(g.az + k)));
    const __m256 e4 = _mm256_mul_ps(_mm256_set1_ps(4.0f), e2);
    if (pointwise) exact_squares(x, y, z, g.ax + k, g.ay + k, g.az + k, pointwise + k);
    const __m256 before = segment_dist2_avx2(g, x, y, z, k - 1), after = segment_dist2_avx2(g, x, y, z, k);
    const __m256 later = _mm256_cmp_ps(after, before, _CMP_LT_OQ);
    _mm256_storeu_ps(nearest + k, _mm256_blendv_ps(before, after, later));  // after < before ? after : before
    __m256 ok = _mm256_and_ps(within_half_step(e4, g.uu + k - 1), within_half_step(e4, g.uu + k));
    if constexpr (!kSmooth) {
        // Segments k + 1 .. k + 3 not against k, and k - 4 .. k - 2 not against k - 1.
        const float *f0 = forward[0], *f1 = forward[1], *f2 = forward[2];
        const __m256 ahead =
            _mm256_and_ps(_mm256_and_ps(_mm256_loadu_ps(f0 + k), _mm256_loadu_ps(f1 + k)), _mm256_loadu_ps(f2 + k));
        const __m256 behind = _mm256_and_ps(_mm256_and_ps(_mm256_loadu_ps(f0 + k - 2), _mm256_loadu_ps(f1 + k - 3)),
                                            _mm256_loadu_ps(f2 + k - 4));
        ok = _mm256_and_ps(ok, _mm256_and_ps(ahead, behind));
    }
    store_mask_bytes(ok, proven + k);
    store_mask_bytes(later, later_out + k);
}

// own_segments_at for points [4, n) of a pair of at least 12 points, eight
// at a time; the last eight overlap the ones before where the count is not
// a multiple of 8 (the same values stored again), so no point is left for
// own_segments_at.
template <bool kSmooth>
__attribute__((target("avx2"))) void own_segments_avx2(const Segments& to_g, const Segments& from_g, float* nearest,
                                                       double* pointwise, OwnSegments& out) {
    const ColumnPointers g(to_g), p(from_g);
    const float* const forward[3] = {out.forward[0].data(), out.forward[1].data(), out.forward[2].data()};
    std::uint8_t *proven = out.proven.data(), *later = out.later.data();
    const std::size_t n = to_g.count;
    std::size_t k = 4;
    for (; k + 8 <= n; k += 8) own_segments8<kSmooth>(g, p, forward, k, nearest, pointwise, proven, later);
    if (k < n) own_segments8<kSmooth>(g, p, forward, n - 8, nearest, pointwise, proven, later);
}
#undef FIBLET_AVX2
#endif

// own_segments_at for every point of a fixed-step pair (from_g: the
// columns of `from`, g those of `to`); pointwise[k] = |from[k] - to[k]|^2.
void own_segments(const Segments& g, const Segments& from_g, std::span<const Vec3f> from, std::span<const Vec3f> to,
                  float* nearest, double* pointwise, OwnSegments& out) {
    const std::size_t n = g.count, points = n + 1;  // to.size() == from.size() == n + 1
    grow(out.later, points), grow(out.proven, points);
    std::size_t k = 0;
#ifdef FIBLET_POINTS_AVX2
    // The vector loop reads segments k - 4 .. k + 7 and lengths to k + 7.
    if (use_avx2_loops() && n >= 12) {
        const bool smooth = smooth_avx2(g);
        if (!smooth) forward_avx2(g, out);
        for (; k < 4; ++k) own_segments_at(g, from, to, k, nearest, pointwise, out);
        if (smooth)
            own_segments_avx2<true>(g, from_g, nearest, pointwise, out);
        else
            own_segments_avx2<false>(g, from_g, nearest, pointwise, out);
        k = n;
    }
#endif
    for (; k < points; ++k) own_segments_at(g, from, to, k, nearest, pointwise, out);
}

// The end of the run of proven points from k (bytes 0 or 1), eight at a
// time while they all are.
std::size_t proven_run_end(const std::uint8_t* proven, std::size_t k, std::size_t n) {
    constexpr std::uint64_t kAllProven = 0x0101010101010101ull;
    for (std::uint64_t w; k + 8 <= n; k += 8) {
        std::memcpy(&w, proven + k, 8);
        if (w != kAllProven) break;
    }
    while (k < n && proven[k]) ++k;
    return k;
}

// The roots of n squared distances into `out` (in float, as
// add_all_roots), and the pointwise squares, the roots scaled back by
// unscale and the squares by unscale^2 (exact, in double) where the pair
// was measured scaled (scale_exponent, below).
void add_squares(ErrorStats& out, const float* squares, std::size_t n, std::uint64_t fiber, double* pointwise,
                 double unscale) {
    if (unscale == 1.0) return out.add_all_roots(squares, n, fiber);
    thread_local std::vector<double> unscaled;
    double* u = grow(unscaled, n);
    for (std::size_t k = 0; k < n; ++k) u[k] = double(std::sqrt(squares[k])) * unscale;
    out.add_all(u, n, fiber);
    if (pointwise)
        for (std::size_t k = 0; k < n; ++k) pointwise[k] *= unscale * unscale;
}

// Every point of `from` against the polyline `to` (its columns g; from_g:
// those of `from`, for fixed-step pairs), in order along both, so the
// nearest segment moves forward with the point: the segments within reach
// of the last nearest one are searched (squared distances, one square root
// per point; this runs on every point `compress` writes): two segments
// back, and ahead the segments one step of `from` can cross plus two.
// Returns the length of `to`.
//
// Fixed-step files (as many points as the polyline): point k's window is
// [hint - 2, hint + 4) and the hint stays at k - 1 or k, so the kLanes
// segments from k - 4 are evaluated first, independently of the hint (the
// points' evaluations overlap instead of waiting on each other's nearest
// segment); the nearest one is then chosen from the same window as always,
// or evaluated directly where the window leaves those kLanes. The result is
// the same, bit for bit. `pointwise` (when given, and the polylines have as
// many points): |from[k] - to[k]|^2 for each k. `unscale`: 2^-k for a pair
// measured scaled by 2^k.
double points_to_polyline(std::span<const Vec3f> from, const Segments& from_g, std::span<const Vec3f> to,
                          const Segments& g, ErrorStats& out, std::uint64_t fiber, double* pointwise, double unscale) {
    if (to.empty()) return 0;
    if (from.empty()) return g.length;
    const std::size_t n = g.count;
    const std::size_t ahead = 2 + (to.size() + from.size() - 1) / from.size();
    thread_local std::vector<float> d2;
    grow(d2, ahead + 3);
    float* d = d2.data();
    std::size_t hint = 0;
    const bool same_count = from.size() == to.size() && to.size() > 1 && detail::geometry_shortcut_enabled();
    const bool paired = from.size() == to.size() && use_avx2_loops();
    alignas(32) float lanes[kLanes];
#ifdef FIBLET_POINTS_AVX2
    const ColumnPointers columns(g);
#endif
    thread_local std::vector<float> nearest_buffer;  // squared distances
    float* const nearest = grow(nearest_buffer, from.size());
    thread_local OwnSegments own;
    if (same_count)
        own_segments(g, from_g, from, to, nearest, pointwise, own);
    else if (pointwise && from.size() == to.size())
        for (std::size_t k = 0; k < from.size(); ++k) pointwise[k] = distance2(from[k], to[k]);
    const std::uint8_t *proven = own.proven.data(), *later = own.later.data();
    // Polylines of different point counts may be spaced unevenly (a sparse
    // input resampled: 0.2 mm segments, then 20 mm ones): the window reaches
    // ahead along `to` by at least the distance the nearest point can have
    // moved, 2 (|p_k - p_k-1| + d_k-1), in arc length (cumulative lengths).
    const bool uneven = from.size() != to.size();
    thread_local std::vector<double> arc_buffer;
    double* const arc = uneven ? grow(arc_buffer, n + 1) : nullptr;
    if (uneven) {
        arc[0] = 0;
        for (std::size_t s = 0; s < n; ++s) arc[s + 1] = arc[s] + g.len[s];
    }
    for (std::size_t k = 0; k < from.size(); ++k) {
        if (same_count && proven[k] && hint <= k && hint + 2 >= k) {
            // The window's nearest is k - 1 or k (the first on a tie, as
            // below), already in nearest[k]; so is every proven point's
            // after it, whose hint is then within reach.
            const std::size_t end = proven_run_end(proven, k + 1, from.size());
            hint = end - 2 + later[end - 1];
            k = end - 1;
            continue;
        }
        const Vec3f& p = from[k];
        std::size_t hi = std::min(n, hint + ahead + 1);
        if (uneven && k > 0) {
            const double moved = 2 * (distance(from[k], from[k - 1]) + std::sqrt(double(nearest[k - 1])));
            while (hi < n && arc[hi] - arc[hint] < moved) ++hi;
            grow(d2, hi - hint + 3);
            d = d2.data();
        }
        const std::size_t lo = hint > 2 ? hint - 2 : 0, w = hi - lo;
        float best = std::numeric_limits<float>::infinity();
#ifdef FIBLET_POINTS_AVX2
        if (paired) {
            const std::size_t base = k >= 4 ? k - 4 : 0;
            window_avx2(columns, p.x, p.y, p.z, base, lanes);
            if (lo >= base && hi <= base + kLanes) {
                for (std::size_t s = lo; s < hi; ++s)
                    if (lanes[s - base] < best) best = lanes[s - base], hint = s;
                nearest[k] = best;
                continue;
            }
        }
#endif
        for (std::size_t j = 0; j < w; ++j) d[j] = segment_dist2(g, p.x, p.y, p.z, lo + j);
        for (std::size_t j = 0; j < w; ++j)
            if (d[j] < best) best = d[j], hint = lo + j;
        nearest[k] = best;
    }
    add_squares(out, nearest, from.size(), fiber, pointwise, unscale);
    return g.length * unscale;
}

// The distances are float arithmetic on differences of the two polylines'
// points (segments, errors), whatever the coordinates: their squares
// overflow beyond ~1e19 and lose precision below ~1e-19 (turn statistics
// and the encoder handle any units: docs/encode.md). A pair whose longest
// segment or end displacement m (double) is outside [2^-40, 2^60] is measured
// scaled by the power of two that takes m into [1, 2), which float
// arithmetic commutes with (the same figures, scaled, as long as nothing
// overflows or underflows), then scaled back in double. The scale is 1
// otherwise (every tractogram in millimetres, metres or micrometres,
// wherever its origin).
int scale_exponent(const Segments& a, const Segments& b, double first_end, double last_end) {
    const double m = std::max({a.max_len, b.max_len, first_end, last_end});
    if (!(m > 0) || !std::isfinite(m) || (m >= 0x1p-40 && m <= 0x1p60)) return 0;
    return -std::ilogb(m);
}

// `line` times 2^k into `out`.
std::span<const Vec3f> scaled(std::span<const Vec3f> line, int k, std::vector<Vec3f>& out) {
    out.resize(line.size());
    for (std::size_t i = 0; i < line.size(); ++i)
        out[i] = {std::ldexp(line[i].x, k), std::ldexp(line[i].y, k), std::ldexp(line[i].z, k)};
    return out;
}

}  // namespace

bool& detail::geometry_shortcut_enabled() {
    thread_local bool enabled = true;
    return enabled;
}

bool detail::forward_tests_skipped(std::span<const Vec3f> line) {
#ifdef FIBLET_POINTS_AVX2
    if (!use_avx2_loops() || line.empty()) return false;
    Segments g;
    segments_of(line, g);
    return smooth_avx2(g);
#else
    (void)line;
    return false;
#endif
}


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

void GeometryError::add_fiber(std::span<const Vec3f> input, std::span<const Vec3f> decoded, std::uint64_t fiber,
                              std::span<double> pointwise) {
    if (!pointwise.empty() && (pointwise.size() != input.size() || decoded.size() != input.size()))
        throw Error(Errc::invalid_argument, "GeometryError::add_fiber: pointwise needs one value per point of both polylines");
    thread_local Segments input_segments, decoded_segments;  // each polyline's columns, once
    thread_local std::vector<Vec3f> input_scaled, decoded_scaled;
    if (!input.empty()) segments_of(input, input_segments);
    if (!decoded.empty()) segments_of(decoded, decoded_segments);
    const bool both = !input.empty() && !decoded.empty();
    const double first_end = both ? distance(input.front(), decoded.front()) : 0.0;
    const double last_end = both ? distance(input.back(), decoded.back()) : 0.0;
    const int k = both ? scale_exponent(input_segments, decoded_segments, first_end, last_end) : 0;
    std::span<const Vec3f> in = input, dec = decoded;
    if (k) {  // rare: the columns again, scaled
        in = scaled(input, k, input_scaled), dec = scaled(decoded, k, decoded_scaled);
        if (!in.empty()) segments_of(in, input_segments);
        if (!dec.empty()) segments_of(dec, decoded_segments);
    }
    const double unscale = std::ldexp(1.0, -k);
    const double li = points_to_polyline(dec, decoded_segments, in, input_segments, decoded_to_input_, fiber, nullptr, unscale);
    const double ld = points_to_polyline(in, input_segments, dec, decoded_segments, input_to_decoded_, fiber,
                                         pointwise.empty() ? nullptr : pointwise.data(), unscale);
    if (!both) return;
    endpoint_.add(first_end, fiber);
    endpoint_.add(last_end, fiber);
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
