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

#include "core/points_avx2.hpp"
#include "core/sum_lanes.hpp"
#include "core/vec_math.hpp"
#include "stats/geometry_paths.hpp"

namespace fiblet {

using detail::distance;
using detail::distance2;

namespace {

// The segments of a polyline as columns (start, direction, inverse squared
// length, length), computed once per fiber: the window of segments a point
// is measured against is evaluated as one vectorizable loop, and the points
// of a fixed-step pair are read from their own polyline's columns. The
// polyline's length comes with them (the same double arithmetic and order
// as polyline_length).
constexpr std::size_t kLanes = 8;
// Padding segments after the last (the vector loops read up to 11 past it).
constexpr std::size_t kPadding = 16;

#ifdef FIBLET_POINTS_AVX2
#define FIBLET_AVX2 __attribute__((target("avx2"))) inline
#endif

using detail::use_avx2_loops;
using detail::use_avx512_loops;

#ifdef FIBLET_POINTS_AVX2
__attribute__((target("avx2"))) std::size_t sqrt_avx2(double* v, std::size_t n) {
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) _mm256_storeu_pd(v + i, _mm256_sqrt_pd(_mm256_loadu_pd(v + i)));
    return i;
}
#endif

// v[i] = sqrt(v[i]), four or two at a time (vsqrtpd and sqrtpd round
// correctly, as std::sqrt does).
void sqrt_all(double* v, std::size_t n) {
    std::size_t i = 0;
#ifdef FIBLET_POINTS_AVX2
    if (use_avx2_loops()) i = sqrt_avx2(v, n);
#endif
#ifdef __SSE2__
    for (; i + 2 <= n; i += 2) _mm_storeu_pd(v + i, _mm_sqrt_pd(_mm_loadu_pd(v + i)));
#endif
    for (; i < n; ++i) v[i] = std::sqrt(v[i]);
}

// The per-fiber buffers are thread_local and only ever grow: resizing a
// vector up fills the new elements, which the code then overwrites (that
// fill cost as much as a tenth of the metrics).
template <class T>
T* at_least(std::vector<T>& v, std::size_t n) {
    if (v.size() < n) v.resize(n);
    return v.data();
}

struct Segments {
    std::vector<double> ax, ay, az, ux, uy, uz, inv_uu, len;
    std::size_t count = 0;  // segments (the columns hold kLanes padding segments more)
    double length = 0;
};

// From squared lengths uu (in len): inv[i] = uu > 0 ? 1 / uu : 0, then
// len[i] = sqrt(uu).
void inverses_and_roots(double* len, double* inv, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) inv[i] = len[i] > 0 ? 1.0 / len[i] : 0.0;
    sqrt_all(len, n);
}

// Squared distance of p to segment s (its start when it has no length): the
// arithmetic of every distance here.
inline double segment_dist2(const Segments& g, double px, double py, double pz, std::size_t s) {
    const double wx = px - g.ax[s], wy = py - g.ay[s], wz = pz - g.az[s];
    double t = (wx * g.ux[s] + wy * g.uy[s] + wz * g.uz[s]) * g.inv_uu[s];
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    const double dx = wx - t * g.ux[s], dy = wy - t * g.uy[s], dz = wz - t * g.uz[s];
    return dx * dx + dy * dy + dz * dz;
}

#ifdef FIBLET_POINTS_AVX2
// A polyline's columns as plain pointers: the vector loops keep them in
// registers (their stores may alias a std::vector's, which the compiler
// would otherwise reload after each).
struct ColumnPointers {
    const double *ax, *ay, *az, *ux, *uy, *uz, *inv_uu, *len;
    explicit ColumnPointers(const Segments& g)
        : ax(g.ax.data()), ay(g.ay.data()), az(g.az.data()), ux(g.ux.data()), uy(g.uy.data()), uz(g.uz.data()),
          inv_uu(g.inv_uu.data()), len(g.len.data()) {}
};

// segment_dist2 of the points (x, y, z) to segments s .. s + 3: the same
// double operations in the same order (max(0, t) and min(1, t) return t
// for a NaN and keep -0, as the ternaries do; no fused multiply-add:
// -ffp-contract=off).
FIBLET_AVX2 __m256d segment_dist2_avx2(const ColumnPointers& g, __m256d x, __m256d y, __m256d z, std::size_t s) {
    const __m256d ux = _mm256_loadu_pd(g.ux + s), uy = _mm256_loadu_pd(g.uy + s), uz = _mm256_loadu_pd(g.uz + s);
    const __m256d wx = _mm256_sub_pd(x, _mm256_loadu_pd(g.ax + s)), wy = _mm256_sub_pd(y, _mm256_loadu_pd(g.ay + s)),
                  wz = _mm256_sub_pd(z, _mm256_loadu_pd(g.az + s));
    __m256d t = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(wx, ux), _mm256_mul_pd(wy, uy)), _mm256_mul_pd(wz, uz));
    t = _mm256_min_pd(_mm256_set1_pd(1.0),
                      _mm256_max_pd(_mm256_setzero_pd(), _mm256_mul_pd(t, _mm256_loadu_pd(g.inv_uu + s))));
    const __m256d dx = _mm256_sub_pd(wx, _mm256_mul_pd(t, ux)), dy = _mm256_sub_pd(wy, _mm256_mul_pd(t, uy)),
                  dz = _mm256_sub_pd(wz, _mm256_mul_pd(t, uz));
    return detail::norm2(dx, dy, dz);
}

// Squared distances of p to the kLanes segments from `base` into d.
FIBLET_AVX2 void window_avx2(const ColumnPointers& g, double px, double py, double pz, std::size_t base, double* d) {
    const __m256d x = _mm256_set1_pd(px), y = _mm256_set1_pd(py), z = _mm256_set1_pd(pz);
    for (std::size_t h = 0; h < kLanes; h += 4) _mm256_storeu_pd(d + h, segment_dist2_avx2(g, x, y, z, base + h));
}

// Lanes 1 2 3 of a and lane 0 of b: the next point of each lane.
FIBLET_AVX2 __m256d next_points(__m256d a, __m256d b) {
    return _mm256_shuffle_pd(a, _mm256_permute2f128_pd(a, b, 0x21), 0b0101);
}

// The columns of segments [0, s) in one pass, four at a time (each point
// converted once): starts, directions, inv_uu = uu > 0 ? 1 / uu : 0 and
// len = sqrt(uu), the scalar loops' double operations (vdivpd and vsqrtpd
// round correctly, as / and std::sqrt do; the mask keeps +0, as the
// ternary). Reads points up to s + 4; returns s.
__attribute__((target("avx2"))) std::size_t columns_avx2(const Vec3f* p, std::size_t points, Segments& g) {
    double *ax = g.ax.data(), *ay = g.ay.data(), *az = g.az.data(), *ux = g.ux.data(), *uy = g.uy.data(),
           *uz = g.uz.data(), *inv = g.inv_uu.data(), *len = g.len.data();
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
    std::size_t s = 0;
    if (points < 8) return 0;
    __m256d x, y, z;
    detail::xyz4(p, x, y, z);
    for (; s + 8 <= points; s += 4) {
        __m256d nx, ny, nz;
        detail::xyz4(p + s + 4, nx, ny, nz);
        const __m256d dx = _mm256_sub_pd(next_points(x, nx), x), dy = _mm256_sub_pd(next_points(y, ny), y),
                      dz = _mm256_sub_pd(next_points(z, nz), z);
        const __m256d uu = detail::norm2(dx, dy, dz);
        _mm256_storeu_pd(ax + s, x), _mm256_storeu_pd(ay + s, y), _mm256_storeu_pd(az + s, z);
        _mm256_storeu_pd(ux + s, dx), _mm256_storeu_pd(uy + s, dy), _mm256_storeu_pd(uz + s, dz);
        _mm256_storeu_pd(inv + s, _mm256_and_pd(_mm256_cmp_pd(uu, zero, _CMP_GT_OQ), _mm256_div_pd(one, uu)));
        _mm256_storeu_pd(len + s, _mm256_sqrt_pd(uu));
        x = nx, y = ny, z = nz;
    }
    return s;
}
#endif

// A non-empty polyline's columns.
void segments_of(std::span<const Vec3f> line, Segments& out) {
    const std::size_t points = line.size(), n = points > 1 ? points - 1 : 1;  // a single point: one degenerate segment
    double *ax = at_least(out.ax, n + kPadding), *ay = at_least(out.ay, n + kPadding), *az = at_least(out.az, n + kPadding);
    double *ux = at_least(out.ux, n + kPadding), *uy = at_least(out.uy, n + kPadding), *uz = at_least(out.uz, n + kPadding);
    double *inv = at_least(out.inv_uu, n + kPadding), *len = at_least(out.len, n);
    // The points (segment s runs from point s to point s + 1); segments
    // [0, done) complete from the vector loop.
    std::size_t done = 0;
#ifdef FIBLET_POINTS_AVX2
    if (use_avx2_loops()) done = columns_avx2(line.data(), points, out);
#endif
    for (std::size_t i = done; i < points; ++i) ax[i] = line[i].x, ay[i] = line[i].y, az[i] = line[i].z;
    for (std::size_t s = done; s < n; ++s) {
        const std::size_t e = std::min(s + 1, points - 1);
        const double dx = ax[e] - ax[s], dy = ay[e] - ay[s], dz = az[e] - az[s];
        ux[s] = dx, uy[s] = dy, uz[s] = dz;
        len[s] = dx * dx + dy * dy + dz * dz;
    }
    // Padding segments far away (their squared distance is +inf, never a
    // nearest one), so a window of up to kLanes segments is always
    // evaluated whole.
    for (std::size_t p = n; p < n + kPadding; ++p) {
        ax[p] = ay[p] = az[p] = 1e300;
        ux[p] = uy[p] = uz[p] = inv[p] = 0.0;
    }
    // The inverse squared lengths, and the lengths.
    inverses_and_roots(len + done, inv + done, n - done);
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
    std::vector<double> forward[3];     // vector loops: all bits set where u_s . u_(s + d + 1) >= 0
};

// Point k of own_segments (any k; the edges of the fiber and machines
// without AVX2): its squared distance into nearest[k].
void own_segments_at(const Segments& g, std::span<const Vec3f> from, std::span<const Vec3f> to, std::size_t k,
                     double* nearest, double* pointwise, OwnSegments& out) {
    const std::size_t n = g.count;
    auto dot = [&](std::size_t a, std::size_t b) { return g.ux[a] * g.ux[b] + g.uy[a] * g.uy[b] + g.uz[a] * g.uz[b]; };
    const Vec3f p = from[k];
    const double e2 = distance2(p, to[k]), e4 = 4 * e2;
    pointwise[k] = e2;
    bool proven = true;
    double before = std::numeric_limits<double>::infinity(), after = before;
    if (k > 0) {  // segment k - 1 and the three before it
        before = segment_dist2(g, p.x, p.y, p.z, k - 1);
        proven = proven && e4 < 0.98 * g.len[k - 1] * g.len[k - 1];
        for (std::size_t j = k >= 4 ? k - 4 : 0; j + 1 < k; ++j) proven = proven && dot(j, k - 1) >= 0;
    }
    if (k < n) {  // segment k and the three after it (the padding's direction is 0)
        after = segment_dist2(g, p.x, p.y, p.z, k);
        proven = proven && e4 < 0.98 * g.len[k] * g.len[k];
        for (std::size_t j = k + 1; j <= k + 3; ++j) proven = proven && dot(j, k) >= 0;
    }
    out.later[k] = after < before;
    nearest[k] = after < before ? after : before;
    out.proven[k] = proven;
}

#ifdef FIBLET_POINTS_AVX2
// OwnSegments::forward of every segment: each pair of segments up to three
// apart is tested once, not once for each point it proves.
__attribute__((target("avx2"))) void forward_avx2(const Segments& g, OwnSegments& out) {
    const std::size_t n = g.count;
    // Pointers in locals, as in forward_avx512 (the stores may alias the
    // vectors, and reloading them went through TLS calls: 16 % of the report).
    double* forward[3];
    for (std::size_t d = 0; d < 3; ++d) forward[d] = at_least(out.forward[d], n + 8);
    const double *ux = g.ux.data(), *uy = g.uy.data(), *uz = g.uz.data();
    for (std::size_t s = 0; s < n; s += 4)  // reads up to segment n + 5: padding
        for (std::size_t d = 0; d < 3; ++d) {
            const std::size_t a = s + d + 1;  // u_a . u_s >= 0: not against each other
            const __m256d dot = _mm256_add_pd(
                _mm256_add_pd(_mm256_mul_pd(_mm256_loadu_pd(ux + a), _mm256_loadu_pd(ux + s)),
                              _mm256_mul_pd(_mm256_loadu_pd(uy + a), _mm256_loadu_pd(uy + s))),
                _mm256_mul_pd(_mm256_loadu_pd(uz + a), _mm256_loadu_pd(uz + s)));
            _mm256_storeu_pd(forward[d] + s, _mm256_cmp_pd(dot, _mm256_setzero_pd(), _CMP_GE_OQ));
        }
}

// The four bytes 0 or 1 of a 4-bit mask, lowest bit first.
inline void store_mask_bytes(int mask, std::uint8_t* out) {
    static constexpr std::uint32_t kBytes[16] = {
        0x00000000, 0x00000001, 0x00000100, 0x00000101, 0x00010000, 0x00010001, 0x00010100, 0x00010101,
        0x01000000, 0x01000001, 0x01000100, 0x01000101, 0x01010000, 0x01010001, 0x01010100, 0x01010101};
    std::memcpy(out, &kBytes[mask], 4);  // little-endian: the first byte is bit 0
}

// e4 < 0.98 len^2 for lengths len .. len + 3.
FIBLET_AVX2 __m256d within_half_step(__m256d e4, const double* len4) {
    const __m256d len = _mm256_loadu_pd(len4);
    return _mm256_cmp_pd(e4, _mm256_mul_pd(_mm256_mul_pd(_mm256_set1_pd(0.98), len), len), _CMP_LT_OQ);
}

// own_segments_at for points [k0, k1) (4 <= k0, k1 <= n), four at a time,
// the points read from both polylines' columns: the same distances bit for
// bit, the same proof.
__attribute__((target("avx2"))) void own_segments_avx2(const Segments& to_g, const Segments& from_g,
                                                       std::span<const Vec3f> from, std::span<const Vec3f> to,
                                                       std::size_t k0, std::size_t k1, double* nearest,
                                                       double* pointwise, OwnSegments& out) {
    const ColumnPointers g(to_g), p(from_g);
    const double *f0 = out.forward[0].data(), *f1 = out.forward[1].data(), *f2 = out.forward[2].data();
    std::uint8_t *proven = out.proven.data(), *later_out = out.later.data();
    std::size_t k = k0;
    for (; k + 4 <= k1; k += 4) {
        const __m256d x = _mm256_loadu_pd(p.ax + k), y = _mm256_loadu_pd(p.ay + k), z = _mm256_loadu_pd(p.az + k);
        const __m256d ex = _mm256_sub_pd(x, _mm256_loadu_pd(g.ax + k)), ey = _mm256_sub_pd(y, _mm256_loadu_pd(g.ay + k)),
                      ez = _mm256_sub_pd(z, _mm256_loadu_pd(g.az + k));
        const __m256d e2 = detail::norm2(ex, ey, ez), e4 = _mm256_mul_pd(_mm256_set1_pd(4.0), e2);
        _mm256_storeu_pd(pointwise + k, e2);
        const __m256d before = segment_dist2_avx2(g, x, y, z, k - 1), after = segment_dist2_avx2(g, x, y, z, k);
        const __m256d later = _mm256_cmp_pd(after, before, _CMP_LT_OQ);
        _mm256_storeu_pd(nearest + k, _mm256_blendv_pd(before, after, later));  // after < before ? after : before
        // Segments k + 1 .. k + 3 not against k, and k - 4 .. k - 2 not against k - 1.
        const __m256d ahead =
            _mm256_and_pd(_mm256_and_pd(_mm256_loadu_pd(f0 + k), _mm256_loadu_pd(f1 + k)), _mm256_loadu_pd(f2 + k));
        const __m256d behind = _mm256_and_pd(_mm256_and_pd(_mm256_loadu_pd(f0 + k - 2), _mm256_loadu_pd(f1 + k - 3)),
                                             _mm256_loadu_pd(f2 + k - 4));
        const __m256d ok = _mm256_and_pd(_mm256_and_pd(within_half_step(e4, g.len + k - 1), within_half_step(e4, g.len + k)),
                                         _mm256_and_pd(ahead, behind));
        store_mask_bytes(_mm256_movemask_pd(ok), proven + k);
        store_mask_bytes(_mm256_movemask_pd(later), later_out + k);
    }
    for (; k < k1; ++k) own_segments_at(to_g, from, to, k, nearest, pointwise, out);
}
#undef FIBLET_AVX2

// The AVX-512 twins of forward_avx2 and own_segments_avx2: eight lanes,
// the same double operations.
#define FIBLET_AVX512 __attribute__((target("avx512f,avx512dq,avx512bw,avx512vl"))) inline
FIBLET_AVX512 __m512d column8(const double* c, std::size_t s) { return _mm512_loadu_pd(c + s); }

FIBLET_AVX512 __m512d norm2_8(__m512d dx, __m512d dy, __m512d dz) {
    return _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)), _mm512_mul_pd(dz, dz));
}

// segment_dist2_avx2 for segments s .. s + 7 (vmaxpd and vminpd return
// their second operand for a NaN, as the 256-bit ones).
FIBLET_AVX512 __m512d segment_dist2_avx512(const ColumnPointers& g, __m512d x, __m512d y, __m512d z, std::size_t s) {
    const __m512d ux = column8(g.ux, s), uy = column8(g.uy, s), uz = column8(g.uz, s);
    const __m512d wx = _mm512_sub_pd(x, column8(g.ax, s)), wy = _mm512_sub_pd(y, column8(g.ay, s)),
                  wz = _mm512_sub_pd(z, column8(g.az, s));
    __m512d t = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(wx, ux), _mm512_mul_pd(wy, uy)), _mm512_mul_pd(wz, uz));
    t = _mm512_min_pd(_mm512_set1_pd(1.0), _mm512_max_pd(_mm512_setzero_pd(), _mm512_mul_pd(t, column8(g.inv_uu, s))));
    const __m512d dx = _mm512_sub_pd(wx, _mm512_mul_pd(t, ux)), dy = _mm512_sub_pd(wy, _mm512_mul_pd(t, uy)),
                  dz = _mm512_sub_pd(wz, _mm512_mul_pd(t, uz));
    return norm2_8(dx, dy, dz);
}

__attribute__((target("avx512f,avx512dq,avx512bw,avx512vl"))) void forward_avx512(const Segments& g, OwnSegments& out) {
    const std::size_t n = g.count;
    // Pointers in locals: `out` and `g` are thread_local, and with -fPIC the
    // loop reloaded their addresses through TLS calls (spilling every
    // vector register around them) after each store.
    double* forward[3];
    for (std::size_t d = 0; d < 3; ++d) forward[d] = at_least(out.forward[d], n + 8);
    const double *ux = g.ux.data(), *uy = g.uy.data(), *uz = g.uz.data();
    for (std::size_t s = 0; s < n; s += 8)  // reads up to segment n + 10: padding
        for (std::size_t d = 0; d < 3; ++d) {
            const std::size_t a = s + d + 1;
            const __m512d dot = _mm512_add_pd(
                _mm512_add_pd(_mm512_mul_pd(_mm512_loadu_pd(ux + a), _mm512_loadu_pd(ux + s)),
                              _mm512_mul_pd(_mm512_loadu_pd(uy + a), _mm512_loadu_pd(uy + s))),
                _mm512_mul_pd(_mm512_loadu_pd(uz + a), _mm512_loadu_pd(uz + s)));
            const __mmask8 ok = _mm512_cmp_pd_mask(dot, _mm512_setzero_pd(), _CMP_GE_OQ);
            _mm512_storeu_pd(forward[d] + s, _mm512_castsi512_pd(_mm512_movm_epi64(ok)));
        }
}

// Lanes of a forward mask that are set.
FIBLET_AVX512 __mmask8 set_lanes(const double* m, std::size_t s) {
    const __m512i v = _mm512_castpd_si512(_mm512_loadu_pd(m + s));
    return _mm512_test_epi64_mask(v, v);
}

FIBLET_AVX512 __mmask8 within_half_step8(__m512d e4, const ColumnPointers& g, std::size_t s) {
    const __m512d len = column8(g.len, s);
    return _mm512_cmp_pd_mask(e4, _mm512_mul_pd(_mm512_mul_pd(_mm512_set1_pd(0.98), len), len), _CMP_LT_OQ);
}

// own_segments_avx2's loop eight points at a time from k0 (>= 4) while
// eight fit before k1; returns where it stopped.
__attribute__((target("avx512f,avx512dq,avx512bw,avx512vl"))) std::size_t own_segments_avx512(
    const Segments& to_g, const Segments& from_g, std::size_t k0, std::size_t k1, double* nearest, double* pointwise,
    OwnSegments& out) {
    // Pointers in locals, the columns' too, as in forward_avx512.
    const ColumnPointers g(to_g), p(from_g);
    const double* f[3] = {out.forward[0].data(), out.forward[1].data(), out.forward[2].data()};
    std::uint8_t *proven = out.proven.data(), *later_out = out.later.data();
    const __m128i ones = _mm_set1_epi8(1);
    std::size_t k = k0;
    for (; k + 8 <= k1; k += 8) {
        const __m512d x = column8(p.ax, k), y = column8(p.ay, k), z = column8(p.az, k);
        const __m512d e2 = norm2_8(_mm512_sub_pd(x, column8(g.ax, k)), _mm512_sub_pd(y, column8(g.ay, k)),
                                   _mm512_sub_pd(z, column8(g.az, k)));
        const __m512d e4 = _mm512_mul_pd(_mm512_set1_pd(4.0), e2);
        _mm512_storeu_pd(pointwise + k, e2);
        const __m512d before = segment_dist2_avx512(g, x, y, z, k - 1), after = segment_dist2_avx512(g, x, y, z, k);
        const __mmask8 later = _mm512_cmp_pd_mask(after, before, _CMP_LT_OQ);
        _mm512_storeu_pd(nearest + k, _mm512_mask_blend_pd(later, before, after));
        const __mmask8 ahead = set_lanes(f[0], k) & set_lanes(f[1], k) & set_lanes(f[2], k);
        const __mmask8 behind = set_lanes(f[0], k - 2) & set_lanes(f[1], k - 3) & set_lanes(f[2], k - 4);
        const __mmask8 ok = within_half_step8(e4, g, k - 1) & within_half_step8(e4, g, k) & ahead & behind;
        _mm_storel_epi64(reinterpret_cast<__m128i*>(proven + k), _mm_maskz_mov_epi8(ok, ones));
        _mm_storel_epi64(reinterpret_cast<__m128i*>(later_out + k), _mm_maskz_mov_epi8(later, ones));
    }
    return k;
}
#undef FIBLET_AVX512
#endif

// own_segments_at for every point of a fixed-step pair (from_g: the
// columns of `from`, g those of `to`); pointwise[k] = |from[k] - to[k]|^2.
void own_segments(const Segments& g, const Segments& from_g, std::span<const Vec3f> from, std::span<const Vec3f> to,
                  double* nearest, double* pointwise, OwnSegments& out) {
    const std::size_t n = g.count, points = n + 1;  // to.size() == from.size() == n + 1
    at_least(out.later, points), at_least(out.proven, points);
    std::size_t k = 0;
#ifdef FIBLET_POINTS_AVX2
    // The vector loop reads segments k - 4 .. k + 3 and lengths to k + 3.
    if (use_avx2_loops() && n > 8) {
        const bool avx512 = use_avx512_loops();
        avx512 ? forward_avx512(g, out) : forward_avx2(g, out);
        for (; k < 4; ++k) own_segments_at(g, from, to, k, nearest, pointwise, out);
        own_segments_avx2(g, from_g, from, to, avx512 ? own_segments_avx512(g, from_g, 4, n, nearest, pointwise, out) : 4,
                          n, nearest, pointwise, out);
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
// many points): |from[k] - to[k]|^2 for each k.
double points_to_polyline(std::span<const Vec3f> from, const Segments& from_g, std::span<const Vec3f> to,
                          const Segments& g, ErrorStats& out, std::uint64_t fiber, double* pointwise = nullptr) {
    if (to.empty()) return 0;
    if (from.empty()) return g.length;
    const std::size_t n = g.count;
    const std::size_t ahead = 2 + (to.size() + from.size() - 1) / from.size();
    thread_local std::vector<double> d2;
    at_least(d2, ahead + 3);
    double* d = d2.data();
    std::size_t hint = 0;
    const bool same_count = from.size() == to.size() && to.size() > 1 && detail::geometry_shortcut_enabled();
    const bool paired = from.size() == to.size() && use_avx2_loops();
    alignas(32) double lanes[kLanes];
#ifdef FIBLET_POINTS_AVX2
    const ColumnPointers columns(g);
#endif
    thread_local std::vector<double> nearest_buffer;  // squared distances
    double* const nearest = at_least(nearest_buffer, from.size());
    thread_local OwnSegments own;
    thread_local std::vector<double> pointwise_buffer;
    if (same_count)
        own_segments(g, from_g, from, to, nearest, pointwise ? pointwise : at_least(pointwise_buffer, from.size()), own);
    else if (pointwise && from.size() == to.size())
        for (std::size_t k = 0; k < from.size(); ++k) pointwise[k] = distance2(from[k], to[k]);
    const std::uint8_t *proven = own.proven.data(), *later = own.later.data();
    // Polylines of different point counts may be spaced unevenly (a sparse
    // input resampled: 0.2 mm segments, then 20 mm ones): the window reaches
    // ahead along `to` by at least the distance the nearest point can have
    // moved, 2 (|p_k - p_k-1| + d_k-1), in arc length (cumulative lengths).
    const bool uneven = from.size() != to.size();
    thread_local std::vector<double> arc_buffer;
    double* const arc = uneven ? at_least(arc_buffer, n + 1) : nullptr;
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
            const double moved = 2 * (distance(from[k], from[k - 1]) + std::sqrt(nearest[k - 1]));
            while (hi < n && arc[hi] - arc[hint] < moved) ++hi;
            at_least(d2, hi - hint + 3);
            d = d2.data();
        }
        const std::size_t lo = hint > 2 ? hint - 2 : 0, w = hi - lo;
        const double px = p.x, py = p.y, pz = p.z;
        double best = std::numeric_limits<double>::infinity();
#ifdef FIBLET_POINTS_AVX2
        if (paired) {
            const std::size_t base = k >= 4 ? k - 4 : 0;
            window_avx2(columns, px, py, pz, base, lanes);
            if (lo >= base && hi <= base + kLanes) {
                for (std::size_t s = lo; s < hi; ++s)
                    if (lanes[s - base] < best) best = lanes[s - base], hint = s;
                nearest[k] = best;
                continue;
            }
        }
#endif
        for (std::size_t j = 0; j < w; ++j) d[j] = segment_dist2(g, px, py, pz, lo + j);
        for (std::size_t j = 0; j < w; ++j)
            if (d[j] < best) best = d[j], hint = lo + j;
        nearest[k] = best;
    }
    out.add_all_roots(nearest, from.size(), fiber);
    return g.length;
}

}  // namespace

bool& detail::geometry_shortcut_enabled() {
    thread_local bool enabled = true;
    return enabled;
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
    if (!input.empty()) segments_of(input, input_segments);
    if (!decoded.empty()) segments_of(decoded, decoded_segments);
    const double li = points_to_polyline(decoded, decoded_segments, input, input_segments, decoded_to_input_, fiber);
    const double ld = points_to_polyline(input, input_segments, decoded, decoded_segments, input_to_decoded_, fiber,
                                         pointwise.empty() ? nullptr : pointwise.data());
    if (input.empty() || decoded.empty()) return;
    endpoint_.add(distance(input.front(), decoded.front()), fiber);
    endpoint_.add(distance(input.back(), decoded.back()), fiber);
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
