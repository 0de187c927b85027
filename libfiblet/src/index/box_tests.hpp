// The region tests a BlockIndex walks its hierarchy with, each run over
// eight boxes side by side: a node's eight children, or a leaf's eight
// blocks, in one pass without branches instead of eight tests whose outcome
// a branch predictor cannot guess, in core/float_lanes.hpp's vectors of
// four floats, two per side and axis. Every lane does the float operations
// of the one-box test it replaces, in the same order: the same answers bit
// for bit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "core/float_lanes.hpp"
#include "fiblet/block_index.hpp"
#include "fiblet/image_mask.hpp"
#include "fiblet/view.hpp"
#include "index/index_grid.hpp"

namespace fiblet::detail {

enum class Overlap : std::uint8_t { outside, partial, inside };

inline constexpr std::size_t kBoxLanes = kBoxGroupSize;
inline constexpr std::size_t kHalves = kBoxLanes / 4;

// The i-th box of a group as stored, and back.
inline void set_box(BoxGroup& g, std::size_t i, const Aabb& b) {
    g.lo[0][i] = b.min.x, g.lo[1][i] = b.min.y, g.lo[2][i] = b.min.z;
    g.hi[0][i] = b.max.x, g.hi[1][i] = b.max.y, g.hi[2][i] = b.max.z;
}
inline Aabb box_at(const BoxGroup& g, std::size_t i) {
    return {{g.lo[0][i], g.lo[1][i], g.lo[2][i]}, {g.hi[0][i], g.hi[1][i], g.hi[2][i]}};
}

// Lanes 0 of a and b, then lanes 1 (the low 32 bits of four 64-bit words).
inline Ints low_halves(Words a, Words b) {
    return __builtin_shufflevector(reinterpret_cast<Ints>(a), reinterpret_cast<Ints>(b), 0, 2, 4, 6);
}

// n (1 <= n <= kBoxLanes) packed boxes as kBoxLanes: `cells` itself, or,
// for fewer, copied into `padded` with box 0 again past n.
inline const std::uint64_t* eight_cells(const std::uint64_t* cells, std::size_t n, std::uint64_t (&padded)[kBoxLanes]) {
    if (n == kBoxLanes) return cells;
    for (std::size_t i = 0; i < kBoxLanes; ++i) padded[i] = cells[i < n ? i : 0];
    return padded;
}

// kBoxLanes boxes in registers: [axis][half] vectors of their sides.
struct BoxLanes {
    Floats lo[3][kHalves], hi[3][kHalves];

    static BoxLanes of(const BoxGroup& g) {
        BoxLanes b;
        for (int a = 0; a < 3; ++a)
            for (std::size_t h = 0; h < kHalves; ++h)
                std::memcpy(&b.lo[a][h], &g.lo[a][4 * h], sizeof(Floats)),
                    std::memcpy(&b.hi[a][h], &g.hi[a][4 * h], sizeof(Floats));
        return b;
    }
    // One box in every lane.
    static BoxLanes of(const Aabb& box) {
        BoxGroup g;
        for (std::size_t i = 0; i < kBoxLanes; ++i) set_box(g, i, box);
        return of(g);
    }
    // The boxes of n packed grid boxes (1 <= n <= kBoxLanes; cells_bounds'
    // arithmetic, layout L on a grid of cells `cell`), box 0 again in the
    // lanes from n on.
    template <CellLayout L = kGridCells>
    static BoxLanes of_cells(const std::uint64_t* cells, std::size_t n, Vec3f origin, float cell) {
        std::uint64_t padded[kBoxLanes];
        cells = eight_cells(cells, n, padded);
        const float o[3] = {origin.x, origin.y, origin.z}, m = unbounded_box().max.x;
        const float unit = cell / float(L.subdivision);
        constexpr std::uint64_t lo_mask = (1u << L.lo_bits) - 1, extent_mask = (1u << L.extent_bits) - 1;
        BoxLanes b;
        for (std::size_t h = 0; h < kHalves; ++h) {
            Words w0, w1;
            std::memcpy(&w0, cells + 4 * h, sizeof(Words)), std::memcpy(&w1, cells + 4 * h + 2, sizeof(Words));
            const Ints unbounded = low_halves(w0 == kUnboundedCells, w1 == kUnboundedCells);
            for (int a = 0; a < 3; ++a) {
                // cells_lo and cells_hi
                const int shift = int(L.axis_bits()) * a;
                const Ints lo = low_halves((w0 >> shift) & lo_mask, (w1 >> shift) & lo_mask);
                const Ints hi = lo + low_halves((w0 >> (shift + L.lo_bits)) & extent_mask, (w1 >> (shift + L.lo_bits)) & extent_mask);
                const Floats lo_mm = o[a] + __builtin_convertvector(lo, Floats) * unit;
                const Floats hi_mm = o[a] + __builtin_convertvector(hi, Floats) * unit;
                b.lo[a][h] = unbounded ? Floats{} - m : lo_mm;
                b.hi[a][h] = unbounded ? Floats{} + m : hi_mm;
            }
        }
        return b;
    }
    Aabb box(std::size_t i) const {
        const std::size_t h = i / 4, l = i % 4;
        return {{lo[0][h][l], lo[1][h][l], lo[2][h][l]}, {hi[0][h][l], hi[1][h][l], hi[2][h][l]}};
    }
};

// What a box hands the boxes it holds, for tests that narrow down as they
// descend (FrustumTest: the planes it crosses); the others take none.
using Narrowing = std::uint8_t;
inline constexpr Narrowing kEveryPlane = (1u << 6) - 1;  // a frustum's six planes

// Per half: lanes outside (`apart`, -1) or wholly inside (`within`, -1).
struct Verdicts {
    Ints apart[kHalves] = {}, within[kHalves] = {};
    // As Overlap, for the first n lanes.
    void store(std::size_t n, Overlap* out) const {
        for (std::size_t h = 0; h < kHalves; ++h) {
            const Ints codes = apart[h] ? Ints{} : 1 - within[h];  // 0 outside, 1 partial, 2 inside
            for (std::size_t l = 0; l < 4 && 4 * h + l < n; ++l) out[4 * h + l] = Overlap(codes[l]);
        }
    }
};

// A sphere: outside when the box's nearest point is beyond the radius,
// inside when its farthest corner is within it, each with a relative slack
// so float rounding never culls a block whose point passes Region::contains.
struct SphereTest {
    Vec3f c;
    float r2_out, r2_in;
    SphereTest(Vec3f centre, float radius)
        : c(centre), r2_out(radius * radius * (1 + 1e-5f)), r2_in(radius * radius * (1 - 1e-5f)) {}

    void classify(const BoxLanes& b, std::size_t n, Overlap* out) const {
        const float cv[3] = {c.x, c.y, c.z};
        Verdicts v;
        for (std::size_t h = 0; h < kHalves; ++h) {
            Floats near2{}, far2{};
            for (int a = 0; a < 3; ++a) {
                // v < lo ? lo - v : (v > hi ? v - hi : 0), and max(v - lo, hi - v),
                // with std::max's choice (x < y ? y : x) lane by lane
                const Floats below = b.lo[a][h] - cv[a], above = cv[a] - b.hi[a][h], zero{};
                const Floats d = (below < zero ? zero : below) + (above < zero ? zero : above);
                const Floats to_lo = cv[a] - b.lo[a][h], to_hi = b.hi[a][h] - cv[a];
                const Floats f = to_lo < to_hi ? to_hi : to_lo;
                near2 += d * d, far2 += f * f;
            }
            v.apart[h] = near2 > r2_out, v.within[h] = far2 <= r2_in;
        }
        v.store(n, out);
    }
};

// An axis-aligned box.
struct BoxTest {
    Aabb r;
    void classify(const BoxLanes& b, std::size_t n, Overlap* out) const {
        const float rlo[3] = {r.min.x, r.min.y, r.min.z}, rhi[3] = {r.max.x, r.max.y, r.max.z};
        Verdicts v;
        for (std::size_t h = 0; h < kHalves; ++h) {
            v.within[h] = ~Ints{};
            for (int a = 0; a < 3; ++a) {
                v.apart[h] |= (b.hi[a][h] < rlo[a]) | (b.lo[a][h] > rhi[a]);
                v.within[h] &= (b.lo[a][h] >= rlo[a]) & (b.hi[a][h] <= rhi[a]);
            }
        }
        v.store(n, out);
    }
};

// The frustum grown by `margin`: outside when the box's corner farthest
// along some plane's inward normal is beyond the margin
// (box_intersects_frustum), inside when even the nearest corner is within
// the margin of every plane, with room for rounding between corners.
//
// A box wholly inside a plane's side has every box it holds inside it too
// (their nearest corners are no nearer, in float as in exact arithmetic:
// products by the same factor and sums round monotonically), so a node
// hands its children only the planes it crosses (`active`, bit k for plane
// k; each lane's in `children`): deep in the hierarchy a box crosses one
// or two of the six, and the verdicts are those of all six.
struct FrustumTest {
    Frustum f;
    float margin;
    void classify(const BoxLanes& b, std::size_t n, Narrowing active, Overlap* out, Narrowing* children) const {
        Verdicts v;
        Ints crossed[kHalves] = {};
        for (std::size_t h = 0; h < kHalves; ++h) v.within[h] = ~Ints{};
        for (std::size_t k = 0; k < f.planes.size(); ++k) {
            if (!(active >> k & 1)) continue;
            const Plane& p = f.planes[k];
            // The corners' sides, chosen once per plane: far along n, and near.
            const bool x = p.n.x >= 0, y = p.n.y >= 0, z = p.n.z >= 0;
            for (std::size_t h = 0; h < kHalves; ++h) {
                const Floats far = p.n.x * (x ? b.hi : b.lo)[0][h] + p.n.y * (y ? b.hi : b.lo)[1][h] +
                                   p.n.z * (z ? b.hi : b.lo)[2][h] + p.d;
                const Floats near = p.n.x * (x ? b.lo : b.hi)[0][h] + p.n.y * (y ? b.lo : b.hi)[1][h] +
                                    p.n.z * (z ? b.lo : b.hi)[2][h] + p.d;
                const Ints crosses = near < -margin + 1e-3f;
                v.apart[h] |= far < -margin;
                v.within[h] &= ~crosses;
                crossed[h] |= crosses & (1 << k);
            }
        }
        v.store(n, out);
        for (std::size_t i = 0; i < n; ++i) children[i] = Narrowing(crossed[i / 4][i % 4]);
    }
};

// test.classify, with what narrows it where the test takes it.
template <class Test>
void classify(const Test& test, const BoxLanes& b, std::size_t n, Narrowing active, Overlap* out, Narrowing* children) {
    if constexpr (requires { test.classify(b, n, active, out, children); }) test.classify(b, n, active, out, children);
    else test.classify(b, n, out);
}

// An image mask: ImageMask::classify box by box, after its first test
// (the box misses the mask's bounds) made on the eight boxes side by side
// with the same comparisons: about half the boxes a mask query tests end
// there, without a call or a branch each.
struct MaskTest {
    const ImageMask& mask;
    void classify(const BoxLanes& b, std::size_t n, Overlap* out) const {
        const Aabb& m = mask.bounds();
        const float lo[3] = {m.min.x, m.min.y, m.min.z}, hi[3] = {m.max.x, m.max.y, m.max.z};
        for (std::size_t h = 0; h < kHalves; ++h) {
            Ints apart{};
            for (int a = 0; a < 3; ++a) apart |= (b.hi[a][h] < lo[a]) | (b.lo[a][h] > hi[a]);
            for (std::size_t l = 0; l < 4 && 4 * h + l < n; ++l)
                out[4 * h + l] = apart[l] ? Overlap::outside : of(mask.classify(b.box(4 * h + l)));
        }
    }
    static Overlap of(ImageMask::Overlap o) {
        switch (o) {
            case ImageMask::Overlap::outside: return Overlap::outside;
            case ImageMask::Overlap::inside: return Overlap::inside;
            case ImageMask::Overlap::partial: break;
        }
        return Overlap::partial;
    }
};

}  // namespace fiblet::detail
