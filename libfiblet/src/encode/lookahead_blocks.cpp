// The depth-1 lookahead search, one block per SIMD lane (lookahead_blocks.hpp).
// Compiled per x86 target like greedy_blocks.cpp, whose level choice it uses.
#if defined(FIBLET_HAVE_HWY) && defined(__x86_64__)
#define FIBLET_LOOKAHEAD_HWY 1
#define HWY_DISABLED_TARGETS (HWY_SSSE3 | HWY_AVX3_DL)
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "encode/lookahead_blocks.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
//
#include <hwy/highway.h>
#define FIBLET_LOOKAHEAD_ONCE HWY_ONCE
#else
#define FIBLET_LOOKAHEAD_HWY 0
#define FIBLET_LOOKAHEAD_ONCE 1
#endif

#include <cstddef>
#include <cmath>

#include "encode/lookahead_blocks.hpp"

#if FIBLET_LOOKAHEAD_HWY && (HWY_TARGET == HWY_SSE4 || HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3)
#include "encode/code_lanes-inl.hpp"

HWY_BEFORE_NAMESPACE();
namespace fiblet::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// A Rivals record as 32-bit words: x[4], y[4], z[4], pad[4], then the four
// codes (one word) and the count, padded to 20 words.
using Rivals = NearestCodeLut::Rivals;
static_assert(offsetof(Rivals, code) == 16 * sizeof(float) && offsetof(Rivals, count) == 17 * sizeof(float) &&
                  sizeof(Rivals) % sizeof(float) == 0,
              "Rivals are gathered as words");
constexpr int kRivals = 4, kRivalWords = int(sizeof(Rivals) / sizeof(float)), kRivalY = 4, kRivalZ = 8,
              kRivalCodes = 16, kRivalCount = 17;

// Blocks j0 .. j0 + active - 1 of the batch, one per lane of `d`, with
// kDepth (1 or 2) points of lookahead, trying the aim's rival or (kFour)
// the aimed code's four.
template <int kDepth, bool kFour, class D>
void LookaheadVector(D, const Codebook8& cb, float step, const GreedyBatch& batch, std::size_t j0, std::size_t active) {
    static_assert(kDepth == 1 || kDepth == 2, "lanes look one or two points ahead");
    using Lanes = CodeLanes<D>;
    using VF = typename Lanes::VF;
    using VI = typename Lanes::VI;
    const Lanes code(cb);
    BatchLanes<D> s(batch, j0, active);
    const D d = s.d;
    const auto di = code.di;
    const VF stepv = hn::Set(d, step), step2 = hn::Set(d, step * step), two_step = hn::Set(d, 2.0f * step);
    const VF zero = hn::Zero(d), inf = hn::Set(d, INFINITY);
    const float* nb_floats = cb.lut.rivals(0).x;
    const auto* nb_words = reinterpret_cast<const std::int32_t*>(nb_floats);

    // |local|^2 + step^2 (dot_self, then the sum).
    auto base_of = [&](VF x, VF y, VF z) {
        return hn::Add(hn::Add(hn::Add(hn::Mul(x, x), hn::Mul(y, y)), hn::Mul(z, z)), step2);
    };
    // A code's squared error: max0(base - 2 step ((d.x x + d.y y) + d.z z)).
    auto error2 = [&](VF base, VF dx, VF dy, VF dz, VF x, VF y, VF z) {
        const VF dot = hn::Add(hn::Add(hn::Mul(dx, x), hn::Mul(dy, y)), hn::Mul(dz, z));
        return hn::Max(hn::Sub(base, hn::Mul(two_step, dot)), zero);
    };
    // The state after taking the code of frame l from (f, p): nf, q.
    auto take = [&](const VF* f, VF px, VF py, VF pz, const VF* l, VF* nf, VF& qx, VF& qy, VF& qz) {
        Lanes::compose(f, l, nf);
        qx = hn::Add(px, hn::Mul(stepv, nf[0]));
        qy = hn::Add(py, hn::Mul(stepv, nf[1]));
        qz = hn::Add(pz, hn::Mul(stepv, nf[2]));
    };

    // The lanes' targets at points k, k + 1 and (depth 2) k + 2, each gathered once.
    VF tx, ty, tz, nx, ny, nz, ox, oy, oz;
    s.target(s.at, tx, ty, tz);
    if (kDepth == 2) s.target(s.next_at(), nx, ny, nz);
    // Point k's target in the frame and the aim (the aimed code and its
    // rival: CodeLanes::aim): from the state before it (point 0), then as
    // the winning path found them (each path aims from its state at the
    // next target: the same operations).
    VF x, y, z;
    Lanes::local(s.f, hn::Sub(tx, s.px), hn::Sub(ty, s.py), hn::Sub(tz, s.pz), x, y, z);
    VI aim = code.aim(x, y, z);
    for (std::size_t k = 0; k < s.steps; ++k) {
        const VF base = base_of(x, y, z);
        if (kDepth == 1) s.target(s.next_at(), nx, ny, nz);
        else s.target(s.ahead_at(2), ox, oy, oz);
        const auto more = s.more_after(k);                            // lanes with a point k + 1
        const auto more2 = kDepth == 2 ? s.more_after(k + 1) : more;  // and k + 2
        const bool any2 = kDepth == 2 && !hn::AllFalse(d, more2);
        // Code c's state after point k (frame l of c given) into nf, q, and
        // the next target in its frame and the aim at it into x1, y1, z1,
        // aim1; returns the path's sum of squared errors, e0 (c's own) plus
        // greedy aiming's at the points after it (added in the scalar
        // search's order).
        auto path = [&](const VF* l, VF e0, VF* nf, VF& qx, VF& qy, VF& qz, VF& x1, VF& y1, VF& z1, VI& aim1) {
            take(s.f, s.px, s.py, s.pz, l, nf, qx, qy, qz);
            Lanes::local(nf, hn::Sub(nx, qx), hn::Sub(ny, qy), hn::Sub(nz, qz), x1, y1, z1);
            aim1 = code.aim(x1, y1, z1);
            const VI c1 = code.code_of(aim1);
            if (!any2) {
                VF bx, by, bz;
                code.direction(c1, bx, by, bz);
                return hn::Add(e0, error2(base_of(x1, y1, z1), bx, by, bz, x1, y1, z1));
            }
            VF l1[9], f2[9], rx, ry, rz, x2, y2, z2, bx, by, bz;
            code.frame(c1, l1);
            const VF sum1 = hn::Add(e0, error2(base_of(x1, y1, z1), l1[0], l1[1], l1[2], x1, y1, z1));
            take(nf, qx, qy, qz, l1, f2, rx, ry, rz);
            Lanes::local(f2, hn::Sub(ox, rx), hn::Sub(oy, ry), hn::Sub(oz, rz), x2, y2, z2);
            code.direction(code.nearest(x2, y2, z2), bx, by, bz);
            return hn::IfThenElse(more2, hn::Add(sum1, error2(base_of(x2, y2, z2), bx, by, bz, x2, y2, z2)), sum1);
        };
        VF l[9], win_f[9], win_x, win_y, win_z, win_x1, win_y1, win_z1;
        VI win_aim1;
        const VI aimed = code.code_of(aim);
        code.frame(aimed, l);
        const VF aimed_e0 = error2(base, l[0], l[1], l[2], x, y, z);
        VF best = path(l, aimed_e0, win_f, win_x, win_y, win_z, win_x1, win_y1, win_z1, win_aim1);
        VI win_code = aimed;
        // Rival c's path (frame lr, own error e0) where lanes `tries`: it
        // wins with a smaller sum.
        auto try_rival = [&](VI c, const VF* lr, VF e0, hn::Mask<D> tries) {
            VF rf[9], qx, qy, qz, x1, y1, z1;  // the rival's state after point k
            VI aim1;
            const VF total = path(lr, e0, rf, qx, qy, qz, x1, y1, z1, aim1);
            const auto wins = hn::And(tries, hn::Lt(total, best));
            best = hn::IfThenElse(wins, total, best);
            win_code = hn::IfThenElse(hn::RebindMask(di, wins), c, win_code);
            for (int j = 0; j < 9; ++j) win_f[j] = hn::IfThenElse(wins, rf[j], win_f[j]);
            win_x = hn::IfThenElse(wins, qx, win_x), win_y = hn::IfThenElse(wins, qy, win_y);
            win_z = hn::IfThenElse(wins, qz, win_z);
            win_x1 = hn::IfThenElse(wins, x1, win_x1), win_y1 = hn::IfThenElse(wins, y1, win_y1);
            win_z1 = hn::IfThenElse(wins, z1, win_z1), win_aim1 = hn::IfThenElse(hn::RebindMask(di, wins), aim1, win_aim1);
        };
        // The rivals, where a lane has a point after k, each tried while its
        // own error is below the lane's best (the scalar search's branch and
        // bound drops a path once its partial sum reaches the best: errors
        // are at least 0, so such a path's whole sum does not win either).
        if constexpr (!kFour) {
            // One: the aim's (its frame's first column is its direction).
            const VI rival = Lanes::rival_of(aim);
            VF lr[9];
            code.frame(rival, lr);
            const VF e0 = error2(base, lr[0], lr[1], lr[2], x, y, z);
            const auto tries = hn::And(more, hn::Lt(e0, best));
            if (!hn::AllFalse(d, tries)) try_rival(rival, lr, e0, tries);
        } else {
            // The four NearestCodeLut::Rivals of the aimed code, in the
            // scalar search's order: each round takes every lane's cheapest
            // untried rival by own error (the first on a tie); rounds end
            // when no lane has a rival left to try.
            const VI nb_at = hn::Mul(aimed, hn::Set(di, kRivalWords));
            const VI codes = hn::GatherIndex(di, nb_words + kRivalCodes, nb_at);
            const VI count = hn::GatherIndex(di, nb_words + kRivalCount, nb_at);
            VF rival_e0[kRivals], rx[kRivals], ry[kRivals], rz[kRivals];
            GatherFloats(d, nb_floats, nb_at, rx, kRivals);
            GatherFloats(d, nb_floats + kRivalY, nb_at, ry, kRivals);
            GatherFloats(d, nb_floats + kRivalZ, nb_at, rz, kRivals);
            for (int r = 0; r < kRivals; ++r) {
                const auto listed = hn::And(more, hn::RebindMask(d, hn::Lt(hn::Set(di, r), count)));
                rival_e0[r] = hn::IfThenElse(listed, error2(base, rx[r], ry[r], rz[r], x, y, z), inf);
            }
            for (int round = 0; round < kRivals; ++round) {
                VF e0 = rival_e0[0];
                VI which = hn::Zero(di);
                for (int r = 1; r < kRivals; ++r) {
                    const auto lower = hn::Lt(rival_e0[r], e0);
                    e0 = hn::IfThenElse(lower, rival_e0[r], e0);
                    which = hn::IfThenElse(hn::RebindMask(di, lower), hn::Set(di, r), which);
                }
                const auto tries = hn::Lt(e0, best);
                if (hn::AllFalse(d, tries)) break;
                for (int r = 0; r < kRivals; ++r)
                    rival_e0[r] = hn::IfThenElse(hn::RebindMask(d, hn::Eq(which, hn::Set(di, r))), inf, rival_e0[r]);
                // Rival `which`'s code: byte `which` of the codes' word.
                const VI c = hn::And(codes >> hn::ShiftLeft<3>(which), code.byte);
                VF lr[9];
                code.frame(c, lr);
                try_rival(c, lr, e0, tries);
            }
        }
        for (int j = 0; j < 9; ++j) s.f[j] = win_f[j];
        s.px = win_x, s.py = win_y, s.pz = win_z;
        s.store(k, win_code);
        x = win_x1, y = win_y1, z = win_z1, aim = win_aim1;
        tx = nx, ty = ny, tz = nz;
        if (kDepth == 2) nx = ox, ny = oy, nz = oz;
    }
}

template <int kDepth, bool kFour>
std::size_t LookaheadVectors(const Codebook8& cb, float step, const GreedyBatch& batch) {
    return AllVectors(cb, step, batch, [](auto d, auto&&... args) { LookaheadVector<kDepth, kFour>(d, args...); });
}

// The lanes' search for depth 1 or 2, with four rivals or the aim's one.
VectorSearch LookaheadVectorsFor(std::size_t depth, bool four) {
    if (depth == 1) return four ? &LookaheadVectors<1, true> : &LookaheadVectors<1, false>;
    return four ? &LookaheadVectors<2, true> : &LookaheadVectors<2, false>;
}

}  // namespace fiblet::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();
#endif

#if FIBLET_LOOKAHEAD_ONCE
namespace fiblet::detail {
namespace {

// The lanes' search for this depth, rivals and level, if there is one.
VectorSearch vector_search(SimdLevel level, std::size_t depth, LookaheadRivals rivals) {
    if (depth != 1 && depth != 2) return nullptr;
    const bool four = rivals == LookaheadRivals::four;
    switch (level) {
#if FIBLET_LOOKAHEAD_HWY && (HWY_TARGETS & HWY_AVX3)
        case SimdLevel::avx512: return N_AVX3::LookaheadVectorsFor(depth, four);
#endif
#if FIBLET_LOOKAHEAD_HWY && (HWY_TARGETS & HWY_AVX2)
        case SimdLevel::avx2: return N_AVX2::LookaheadVectorsFor(depth, four);
#endif
#if FIBLET_LOOKAHEAD_HWY && (HWY_TARGETS & HWY_SSE4)
        case SimdLevel::sse4: return N_SSE4::LookaheadVectorsFor(depth, four);
#endif
        default: return nullptr;
    }
}

// LookaheadSearch for blocks [first, batch.blocks): four of the same length
// in lockstep (their dependency chains overlap in the CPU), the others one
// at a time.
void scalar_blocks(const Codebook8& cb, float step, std::size_t depth, LookaheadRivals rivals, const GreedyBatch& batch,
                   std::size_t first) {
    constexpr int kLanes = 4;
    LookaheadSearch<Codebook8> lanes[kLanes]{
        {cb, step, depth, rivals}, {cb, step, depth, rivals}, {cb, step, depth, rivals}, {cb, step, depth, rivals}};
    auto start = [&](LookaheadSearch<Codebook8>& lane, std::size_t j) {
        const std::size_t at = j * batch.stride;
        lane.start(batch.frames[j], batch.starts[at], std::span<const Vec3f>(batch.targets + at, batch.length(j)),
                   batch.codes + j * batch.code_stride, batch.decoded + at);
    };
    for (std::size_t j = first; j < batch.blocks;) {
        const std::size_t m = batch.length(j);
        if (j + kLanes <= batch.blocks && batch.length(j + 1) == m && batch.length(j + 2) == m && batch.length(j + 3) == m) {
            for (int i = 0; i < kLanes; ++i) start(lanes[i], j + i);
            while (!lanes[0].done()) LookaheadSearch<Codebook8>::step_lanes<kLanes>(lanes);
            j += kLanes;
            continue;
        }
        start(lanes[0], j);
        while (!lanes[0].done()) lanes[0].step();
        ++j;
    }
}

}  // namespace

void lookahead_blocks(const Codebook8& cb, float step, std::size_t depth, LookaheadRivals rivals,
                      const GreedyBatch& batch) {
    lookahead_blocks(cb, step, depth, rivals, batch, simd_level());
}

void lookahead_blocks(const Codebook8& cb, float step, std::size_t depth, LookaheadRivals rivals,
                      const GreedyBatch& batch, SimdLevel level) {
    require_simd_level(level);
    if (batch.blocks == 0) return;
    std::size_t done = 0;
    if (const VectorSearch search = vector_search(level, depth, rivals); search && lanes_can_take(cb, batch))
        done = search(cb, step, batch);
    scalar_blocks(cb, step, depth, rivals, batch, done);
}

}  // namespace fiblet::detail
#endif
