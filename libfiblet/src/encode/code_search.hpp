// Internal: choosing the direction codes of one block.
//
// The decoder walks p_k = p_{k-1} + step * F_k.c0 with F_k = F_{k-1} *
// frame(code_k); the encoder chooses the codes so that the decoded points
// stay close to the input points t_k. Both searches run the decoder's own
// float operations (closed loop), so the positions they score are the ones
// a decoder will produce, bit for bit.
//
// - greedy (beam width 1): each code is the one aimed most directly at the
//   next input point from the decoded point and frame. Aiming maximizes
//   dot(d, t - p) over unit d, which is the same as minimizing |p + step d - t|.
// - beam search (width W): keeps the W code sequences with the smallest sum
//   of squared point errors so far, expanding each by the (2r+1)^2 codes
//   around its aimed code. A code is thus judged by the errors it causes
//   later in the block too (zig-zag around a straight path, lag, turns
//   sharper than the cap), which greedy aiming cannot see.
// - robust (a second target sequence given): the points must suit two
//   decoders whose first frames differ (exact_model.hpp); the second
//   decoder's error is the distance of the same decoded point to the
//   targets moved by the inverse of that difference. Greedy aims at the
//   middle of the two targets; the beam's cost is the larger of the two
//   squared errors at each point.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "encode/nearest_code_lut.hpp"
#include "encode/row_frame.hpp"
#include "core/vec_math.hpp"
#include "fiblet/direction_code.hpp"

namespace fiblet::detail {

struct SearchParams {
    unsigned beam = 1;    // sequences kept per step; 1 = greedy
    unsigned radius = 1;  // candidate codes: levels within +-radius of the aimed code on both axes
};

// The 8-bit codes of version-2 files, with the fast nearest-code lookup.
struct Codebook8 {
    using Code = std::uint8_t;
    const DirectionTable& table;
    const NearestCodeLut& lut;
    static constexpr int levels() { return 16; }

    Code nearest(Vec3f local) const { return lut.usable() ? lut(local) : table.nearest_code(local); }
    const Frame& frame(unsigned c) const { return table.frame(Code(c)); }
    const Vec3f& direction(unsigned c) const { return table.direction(Code(c)); }
    const RowFrame& rows(unsigned c) const { return lut.rows(Code(c)); }
    const NearestCodeLut::Neighbours& neighbours(unsigned c) const { return lut.neighbours(Code(c)); }
    const NearestCodeLut::Rivals& rivals(unsigned c) const { return lut.rivals(Code(c)); }
    // The nearest code and its rival (NearestCodeLut::Aim).
    NearestCodeLut::Aim aim(Vec3f local) const {
        if (lut.usable()) return lut.aim(local);
        const Code c = table.nearest_code(local);
        return {c, lut.rival(c, local)};
    }
};

// The wide codes of 16-bit files (256 or 181 levels).
struct Codebook16 {
    using Code = std::uint16_t;
    const DirectionTable16& table;
    int levels() const { return int(table.levels()); }

    Code nearest(Vec3f local) const { return table.nearest_code(local); }
    const Frame& frame(unsigned c) const { return table.frame(Code(c)); }
    const Vec3f& direction(unsigned c) const { return table.direction(Code(c)); }
};

inline Vec3f midpoint(Vec3f a, Vec3f b) { return 0.5f * (a + b); }

// How a beam state of step k was reached: links[k * width + j] for state j.
struct BeamLink {
    std::uint32_t parent;
    std::uint32_t code;
};

// A beam search's candidate: a state (`parent`) extended by a code.
struct BeamCandidate {
    float cost;
    std::uint32_t parent;
    std::uint32_t code;
};

// Offers `c` to the step's candidates cand[0, kept): the cand.size()
// cheapest so far, sorted by cost (insertion from the end; most candidates
// are rejected by the first comparison; equal costs keep the order offered).
inline void offer_cheapest(std::span<BeamCandidate> cand, std::size_t& kept, BeamCandidate c) {
    const std::size_t width = cand.size();
    if (kept == width && !(c.cost < cand[width - 1].cost)) return;
    std::size_t i = kept < width ? kept++ : width - 1;
    for (; i > 0 && cand[i - 1].cost > c.cost; --i) cand[i] = cand[i - 1];
    cand[i] = c;
}

// The beam's next states: each kept candidate's parent advanced by its code
// (`advance(parent, code)` gives the new state's frame and point), its cost
// the candidate's; `step_links` records how each was reached.
template <class State, class Advance>
void advance_beam(std::vector<State>& states, std::vector<State>& next, std::span<const BeamCandidate> kept,
                  BeamLink* step_links, std::size_t width, Advance advance) {
    for (std::size_t j = 0; j < kept.size(); ++j) {
        const auto& c = kept[j];
        next[j] = advance(states[c.parent], c.code);
        next[j].cost = c.cost;
        step_links[j] = {c.parent, c.code};
    }
    next.resize(kept.size());
    states.swap(next);
    next.resize(width);
}

// The beam's cheapest final state traced back through its links to its
// codes, which are then replayed from the block's start (f, p) for the
// decoded points.
template <class Codebook, class State>
void backtrack_cheapest(const Codebook& cb, const std::vector<State>& states, const std::vector<BeamLink>& links,
                        std::size_t width, Frame f, Vec3f p, float step, std::size_t m,
                        typename Codebook::Code* codes, Vec3f* decoded) {
    std::uint32_t j = 0;
    for (std::uint32_t s = 1; s < states.size(); ++s)
        if (states[s].cost < states[j].cost) j = s;
    for (std::size_t k = m; k-- > 0;) {
        codes[k] = typename Codebook::Code(links[k * width + j].code);
        j = links[k * width + j].parent;
    }
    for (std::size_t k = 0; k < m; ++k) {
        f = compose(f, cb.frame(codes[k]));
        p = p + step * f.c[0];
        decoded[k] = p;
    }
}

// search_codes' beam (radius 1) for codebooks with frames as rows and
// neighbour tables (Codebook8): the same costs, candidates in the same
// order and the same states, computed four lanes at a time (row_frame.hpp).
template <class Codebook>
void beam_search_rows(const Codebook& cb, unsigned width, Frame f, Vec3f p, float step, std::span<const Vec3f> targets,
                      typename Codebook::Code* codes, Vec3f* decoded, std::span<const Vec3f> alt_targets) {
    const std::size_t m = targets.size();
    const bool robust = !alt_targets.empty();
    struct State {
        RowFrame f;
        F4 p;
        float cost;
    };
    thread_local std::vector<State> states, next;
    thread_local std::vector<BeamCandidate> cand;
    thread_local std::vector<BeamLink> links;  // links[k * width + j]: how state j of step k was reached
    states.assign(1, State{row_frame(f), f4_of(p), 0.0f});
    next.resize(width);
    cand.resize(width);
    links.resize(m * width);
    const float step2 = step * step, two_step = 2.0f * step;
    const F4 two_step4 = f4_set1(two_step), step4 = f4_set1(step);
    alignas(16) float costs[8];

    for (std::size_t k = 0; k < m; ++k) {
        std::size_t kept = 0;
        const F4 target = f4_of(targets[k]), alt_target = robust ? f4_of(alt_targets[k]) : target;
        for (std::uint32_t s = 0; s < states.size(); ++s) {
            const State& st = states[s];
            const F4 local = apply_transposed(st.f, f4_sub(target, st.p));
            const float base = st.cost + dot_self(local) + step2;
            const F4 alt_local = robust ? apply_transposed(st.f, f4_sub(alt_target, st.p)) : local;
            const float alt_base = st.cost + dot_self(alt_local) + step2;
            const unsigned aimed = cb.nearest(robust ? midpoint(vec3_of(local), vec3_of(alt_local)) : vec3_of(local));
            const auto& nb = cb.neighbours(aimed);
            auto lanes = [&](F4 l, float b, int i) {
                const F4 d = f4_add(f4_add(f4_mul(f4_load(nb.x + i), f4_splat<0>(l)), f4_mul(f4_load(nb.y + i), f4_splat<1>(l))),
                                    f4_mul(f4_load(nb.z + i), f4_splat<2>(l)));
                return f4_sub(f4_set1(b), f4_mul(two_step4, d));
            };
            for (int i = 0; i < 8; i += 4) {
                F4 c = lanes(local, base, i);
                if (robust) c = f4_max(c, lanes(alt_local, alt_base, i));
                f4_store(costs + i, c);
            }
            const Vec3f& da = cb.direction(aimed);
            auto dot_a = [&](F4 l) { return da.x * f4_lane<0>(l) + da.y * f4_lane<1>(l) + da.z * f4_lane<2>(l); };
            float aimed_cost = base - two_step * dot_a(local);
            if (robust) aimed_cost = std::max(aimed_cost, alt_base - two_step * dot_a(alt_local));
            // The 3x3 codes in grid order: the neighbours before the aimed
            // code, the aimed code, the rest.
            for (unsigned i = 0; i < nb.before; ++i) offer_cheapest(cand, kept, {costs[i], s, nb.code[i]});
            offer_cheapest(cand, kept, {aimed_cost, s, aimed});
            for (unsigned i = nb.before; i < nb.count; ++i) offer_cheapest(cand, kept, {costs[i], s, nb.code[i]});
        }
        const std::span<const BeamCandidate> step_cand(cand.data(), kept);
        advance_beam(states, next, step_cand, &links[k * width], width, [&](const State& parent, std::uint32_t code) {
            State n;
            n.f = compose(parent.f, cb.rows(code));
            n.p = f4_add(parent.p, f4_mul(step4, axis(n.f)));
            return n;
        });
    }
    backtrack_cheapest(cb, states, links, width, f, p, step, m, codes, decoded);
}

// Chooses codes[k] for targets[k] (normalized coordinates), starting from
// the block's second anchor `p` and first frame `f`; writes the decoded
// points to decoded[k]. `alt_targets`, when not empty, are the second
// decoder's targets (robust search, above).
template <class Codebook>
void search_codes(const Codebook& cb, const SearchParams& sp, Frame f, Vec3f p, float step,
                  std::span<const Vec3f> targets, typename Codebook::Code* codes, Vec3f* decoded,
                  std::span<const Vec3f> alt_targets = {}) {
    using Code = typename Codebook::Code;
    const std::size_t m = targets.size();
    const bool robust = !alt_targets.empty();
    if (sp.beam <= 1) {
        for (std::size_t k = 0; k < m; ++k) {
            const Vec3f aim = robust ? midpoint(targets[k], alt_targets[k]) : targets[k];
            const Code code = cb.nearest(apply_transposed(f, aim - p));
            codes[k] = code;
            f = compose(f, cb.frame(code));
            p = p + step * f.c[0];
            decoded[k] = p;
        }
        return;
    }

    if constexpr (requires { cb.neighbours(0u); }) {
        if (sp.radius == 1) return beam_search_rows(cb, sp.beam, f, p, step, targets, codes, decoded, alt_targets);
    }

    struct State {
        Frame f;
        Vec3f p;
        float cost;
    };
    const unsigned width = sp.beam;
    const int r = int(sp.radius);
    thread_local std::vector<State> states, next;
    thread_local std::vector<BeamCandidate> cand;
    thread_local std::vector<BeamLink> links;  // links[k * width + j]: how state j of step k was reached
    states.assign(1, State{f, p, 0.0f});
    next.resize(width);
    cand.resize(width);
    links.resize(m * width);
    const float step2 = step * step, two_step = 2.0f * step;

    for (std::size_t k = 0; k < m; ++k) {
        std::size_t kept = 0;
        for (std::uint32_t s = 0; s < states.size(); ++s) {
            const State& st = states[s];
            // |p + step d - t|^2 = |t - p|^2 + step^2 - 2 step d.(t - p), and d.(t - p) in
            // the local frame is direction(code).local: three products per candidate.
            const Vec3f local = apply_transposed(st.f, targets[k] - st.p);
            const float base = st.cost + dot(local, local) + step2;
            const Vec3f alt_local = robust ? apply_transposed(st.f, alt_targets[k] - st.p) : local;
            const float alt_base = st.cost + dot(alt_local, alt_local) + step2;
            const unsigned aimed = cb.nearest(robust ? midpoint(local, alt_local) : local);
            const int levels = cb.levels();
            const int h0 = int(aimed) / levels, l0 = int(aimed) % levels;
            for (int h = std::max(h0 - r, 0); h <= std::min(h0 + r, levels - 1); ++h)
                for (int l = std::max(l0 - r, 0); l <= std::min(l0 + r, levels - 1); ++l) {
                    const auto code = std::uint32_t(h * levels + l);
                    float cost = base - two_step * dot(cb.direction(code), local);
                    if (robust) cost = std::max(cost, alt_base - two_step * dot(cb.direction(code), alt_local));
                    offer_cheapest(cand, kept, {cost, s, code});
                }
        }
        const std::span<const BeamCandidate> step_cand(cand.data(), kept);
        advance_beam(states, next, step_cand, &links[k * width], width, [&](const State& parent, std::uint32_t code) {
            State n;
            n.f = compose(parent.f, cb.frame(code));
            n.p = parent.p + step * n.f.c[0];
            return n;
        });
    }
    backtrack_cheapest(cb, states, links, width, f, p, step, m, codes, decoded);
}

// Greedy aiming with lookahead (a "pilot" search): at each point the aimed
// code and its rivals (LookaheadRivals: the aim's one, or the aimed code's
// four nearest) are scored by their own squared error plus the squared
// errors greedy aiming makes at the next `depth` points from where they
// lead; the cheapest wins. It sees what greedy aiming cannot — a code that
// is a little worse now but leaves the frame and the position better placed
// for the next points (the zig-zag around a straight path, the start of a
// turn) — at a few greedy steps per point:
// - rivals are tried in order of their own error and dropped once their
//   partial sum reaches the best (branch and bound: the result is that of
//   trying every rival in full);
// - the aimed code's greedy continuation is kept from one point to the next
//   (a chain of depth + 1 steps, shifted by one when the aimed code wins,
//   replaced by the winner's own continuation otherwise), so the aimed
//   path costs one new greedy step per point.
// History (docs/notes/encode-history.md): eight rivals (the 3x3 around
// the aimed code), then four, then the aim's one where it costs little.
inline constexpr std::size_t kMaxLookahead = 6;

// Which rivals a lookahead search tries besides the aimed code: `aim`, the
// aim's one (NearestCodeLut::Aim), for the first search and the length
// tails; `four`, the aimed code's four NearestCodeLut::Rivals in order of
// their own errors, for the retry, which makes the max error (with one
// rival there the sharpest turns' blocks kept larger errors and the tuning
// chose wider caps: small-ifod1 2.03 -> 2.25 um mean). docs/encode.md.
enum class LookaheadRivals { aim, four };

template <class Codebook>
class LookaheadSearch {
public:
    using Code = typename Codebook::Code;
    LookaheadSearch(const Codebook& cb, float step, std::size_t depth, LookaheadRivals rivals)
        : cb_(cb), step_(step), step2_(step * step), two_step_(2.0f * step), depth_(std::min(depth, kMaxLookahead)),
          rivals_(rivals) {}

    // A block: codes[k] for targets[k] from the second anchor `p` and first
    // frame `f`. `alt_targets`, when not empty, are the second decoder's
    // (robust search, as in search_codes): aims at the middle of the two
    // targets, a step's error is the larger of its two squared errors.
    void start(Frame f, Vec3f p, std::span<const Vec3f> targets, Code* codes, Vec3f* decoded,
               std::span<const Vec3f> alt_targets = {}) {
        f_ = row_frame(f), p_ = f4_of(p), targets_ = targets, alt_ = alt_targets, codes_ = codes, decoded_ = decoded, k_ = 0;
        chain_ = &chains_[0], trial_ = &chains_[1];
        chain_->reset();
    }
    bool done() const { return k_ >= targets_.size(); }
    // Chooses the code of the next point.
    void step() { step_lanes<1>(this); }
    // One step of N searches run in lockstep (lanes[0 .. N): blocks of the
    // same length, started together): the same codes as step() on each,
    // with the lanes' work interleaved phase by phase (the aimed paths,
    // then each round of rivals step by step), so that their long
    // dependency chains (frame -> aim -> nearest code -> frame) overlap in
    // the CPU instead of waiting behind one lane's branchy rival search.
    template <int N>
    static void step_lanes(LookaheadSearch* lanes) {
        const std::size_t k = lanes[0].k_, end = std::min(lanes[0].targets_.size(), k + 1 + lanes[0].depth_);
        for (int i = 0; i < N; ++i) lanes[i].extend(*lanes[i].chain_, k, end);
        if (end > k + 1) choose_lanes<N>(lanes, k, end);
        for (int i = 0; i < N; ++i) {
            LookaheadSearch& l = lanes[i];
            const Step& s = (*l.chain_)[0];
            l.codes_[k] = Code(s.code);
            l.f_ = s.f, l.p_ = s.p;
            l.decoded_[k] = vec3_of(l.p_);
            l.chain_->shift();
            ++l.k_;
        }
    }
    void run(Frame f, Vec3f p, std::span<const Vec3f> targets, Code* codes, Vec3f* decoded,
             std::span<const Vec3f> alt_targets = {}) {
        start(f, p, targets, codes, decoded, alt_targets);
        while (!done()) step();
    }

private:
    // One step of a path: at the point it is for, the target in the frame
    // before the step (local) with its dot(local, local) + step^2 (base),
    // the code taken, its squared error, and the state after it (frame as
    // rows: row_frame.hpp).
    struct Step {
        F4 local, alt_local;  // alt_local: robust search only
        float base, alt_base;
        unsigned code, rival;  // the code taken; the aimed code's rival (NearestCodeLut::Aim)
        float error2;
        RowFrame f;
        F4 p;
    };
    // Steps for points k, k + 1, ... (k: the point being chosen), from
    // s[head]: shifting by one point moves `head`, the steps are copied back
    // to the start only when the buffer's end is reached.
    struct Chain {
        static constexpr std::size_t kCapacity = 4 * (kMaxLookahead + 1);
        Step s[kCapacity];
        std::size_t head = 0, n = 0;
        Step& operator[](std::size_t i) { return s[head + i]; }
        const Step& operator[](std::size_t i) const { return s[head + i]; }
        float sum() const {
            float e = 0;
            for (std::size_t i = 0; i < n; ++i) e += s[head + i].error2;
            return e;
        }
        void shift() { ++head, n = n > 0 ? n - 1 : 0; }
        void reset() { head = 0, n = 0; }
        // Room for `steps` steps from head.
        void reserve(std::size_t steps) {
            if (head + steps <= kCapacity) return;
            for (std::size_t i = 0; i < n; ++i) s[i] = s[head + i];
            head = 0;
        }
    };

    // The state after taking `code` from (f, p): the decoder's operations
    // (p + step * F.c0 with F = compose(f, frame(code))).
    void take(Step& s, unsigned code, const RowFrame& f, F4 p) const {
        s.code = code;
        s.f = compose(f, cb_.rows(code));
        s.p = f4_add(p, f4_mul(f4_set1(step_), axis(s.f)));
    }
    // |p + step d - t|^2 = |t - p|^2 + step^2 - 2 step d.(t - p), in the local frame
    // (base = |t - p|^2 + step^2). Clamped at 0 (rounding can take a tiny
    // error below it) so that partial sums never decrease: the branch and
    // bound below is then exact.
    float error2(F4 local, float base, unsigned code) const {
        const Vec3f& d = cb_.direction(code);
        return max0(base - two_step_ * (d.x * f4_lane<0>(local) + d.y * f4_lane<1>(local) + d.z * f4_lane<2>(local)));
    }
    float error2(const Step& s, unsigned code) const {
        const float e = error2(s.local, s.base, code);
        return alt_.empty() ? e : std::max(e, error2(s.alt_local, s.alt_base, code));
    }
    // error2(s, code) of the 4 rivals' codes (+inf past their count): the
    // same products and sums, four lanes at once.
    void rival_errors(const Step& s, const NearestCodeLut::Rivals& nb, float* out) const {
        const F4 two_step = f4_set1(two_step_), zero = f4_set1(0.0f);
        auto lanes = [&](F4 local, float base) {
            const F4 d = f4_add(f4_add(f4_mul(f4_load(nb.x), f4_splat<0>(local)), f4_mul(f4_load(nb.y), f4_splat<1>(local))),
                                f4_mul(f4_load(nb.z), f4_splat<2>(local)));
            return f4_max(zero, f4_sub(f4_set1(base), f4_mul(two_step, d)));
        };
        F4 e = lanes(s.local, s.base);
        if (!alt_.empty()) e = f4_max(e, lanes(s.alt_local, s.alt_base));
        f4_store(out, f4_add(e, f4_load(nb.pad)));
    }
    // The rivals (rivals_) of the aim in `aim0`, their own errors measured
    // from `first`'s locals (+inf past their count).
    void rivals_of(const Step& aim0, const Step& first, float* error2_out, std::uint8_t* codes) const {
        if (rivals_ == LookaheadRivals::aim) {
            error2_out[0] = error2(first, aim0.rival);
            std::fill_n(error2_out + 1, 3, INFINITY);
            codes[0] = std::uint8_t(aim0.rival);
            return;
        }
        const NearestCodeLut::Rivals& nb = cb_.rivals(aim0.code);
        rival_errors(first, nb, error2_out);
        std::copy_n(nb.code, 4, codes);
    }
    // The greedy step for point j from state (f, p), without its state after.
    void aim(Step& s, std::size_t j, const RowFrame& f, F4 p) const {
        const F4 t = f4_of(targets_[j]);
        s.local = apply_transposed(f, f4_sub(t, p));
        s.base = dot_self(s.local) + step2_;
        NearestCodeLut::Aim a;
        if (alt_.empty()) {
            a = cb_.aim(vec3_of(s.local));
        } else {
            const F4 alt = f4_of(alt_[j]);
            s.alt_local = apply_transposed(f, f4_sub(alt, p));
            s.alt_base = dot_self(s.alt_local) + step2_;
            a = cb_.aim(vec3_of(apply_transposed(f, f4_sub(f4_of(midpoint(targets_[j], alt_[j])), p))));
        }
        s.code = a.code, s.rival = a.rival;
        s.error2 = error2(s, s.code);
    }

    // Greedy steps until the chain covers points k .. end - 1.
    void extend(Chain& c, std::size_t k, std::size_t end) const {
        c.reserve(end - k);
        for (std::size_t j = k + c.n; j < end; ++j) {
            Step& s = c[c.n];
            const RowFrame& fb = c.n ? c[c.n - 1].f : f_;
            const F4 pb = c.n ? c[c.n - 1].p : p_;
            aim(s, j, fb, pb);
            take(s, s.code, fb, pb);
            ++c.n;
        }
    }

    // Replaces each lane's aimed path by a rival's where one is cheaper.
    // Per lane: rivals (LookaheadRivals) are tried cheapest own error
    // first, each path abandoned once its partial sum reaches the lane's best (branch and
    // bound), until the next rival's own error reaches the best. The lanes
    // try their rivals in rounds (round r: every lane's r-th rival, step by
    // step). A rival path's last step is taken (its state computed) only
    // for the path that wins in the end: the losers never need it.
    template <int N>
    static void choose_lanes(LookaheadSearch* lanes, std::size_t k, std::size_t end) {
        struct Lane {
            Step first;  // the aim's locals: copies, chain_ changes hands below
            alignas(16) float rival_error2[4];
            std::uint8_t rival_code[4];
            float best, e;
            bool trying, following, won;
        };
        Lane st[N];
        for (int i = 0; i < N; ++i) {
            LookaheadSearch& l = lanes[i];
            Lane& a = st[i];
            const Step& aim0 = (*l.chain_)[0];
            a.first.local = aim0.local, a.first.alt_local = aim0.alt_local;
            a.first.base = aim0.base, a.first.alt_base = aim0.alt_base;
            l.rivals_of(aim0, a.first, a.rival_error2, a.rival_code);
            a.best = l.chain_->sum();
            a.trying = true, a.won = false;
        }
        for (;;) {
            // Each trying lane's next rival (the cheapest left, by a
            // branch-free scan: most points try none or one), if its own
            // error is below the lane's best.
            bool any = false;
            for (int i = 0; i < N; ++i) {
                Lane& a = st[i];
                a.following = false;
                if (!a.trying) continue;
                unsigned r = 0;
                for (unsigned j = 1; j < 4; ++j) r = a.rival_error2[j] < a.rival_error2[r] ? j : r;
                const float e0 = a.rival_error2[r];
                if (!(e0 < a.best)) {
                    a.trying = false;
                    continue;
                }
                a.rival_error2[r] = INFINITY;
                Chain& t = *lanes[i].trial_;
                t.reset();
                t[0].local = a.first.local, t[0].alt_local = a.first.alt_local;
                t[0].base = a.first.base, t[0].alt_base = a.first.alt_base;
                t[0].error2 = e0;
                t[0].code = a.rival_code[r];
                t.n = 1;
                a.e = e0;
                a.following = any = true;
            }
            if (!any) break;
            // The rivals' paths into trial_, step by step across the lanes;
            // each step's state is computed when the next step needs it
            // (t[t.n - 1]'s is not yet).
            for (std::size_t j = k + 1; j < end; ++j) {
                for (int i = 0; i < N; ++i) {
                    if (!st[i].following) continue;
                    LookaheadSearch& l = lanes[i];
                    Chain& t = *l.trial_;
                    Step& prev = t[t.n - 1];
                    l.take(prev, prev.code, t.n > 1 ? t[t.n - 2].f : l.f_, t.n > 1 ? t[t.n - 2].p : l.p_);
                }
                for (int i = 0; i < N; ++i) {
                    Lane& a = st[i];
                    if (!a.following) continue;
                    LookaheadSearch& l = lanes[i];
                    Chain& t = *l.trial_;
                    Step& s = t[t.n];
                    l.aim(s, j, t[t.n - 1].f, t[t.n - 1].p);
                    a.e += s.error2;
                    if (!(a.e < a.best)) a.following = false;  // abandoned
                    else ++t.n;
                }
            }
            for (int i = 0; i < N; ++i)
                if (st[i].following) st[i].best = st[i].e, st[i].won = true, std::swap(lanes[i].chain_, lanes[i].trial_);
        }
        for (int i = 0; i < N; ++i) {
            if (!st[i].won) continue;
            Chain& c = *lanes[i].chain_;
            Step& last = c[c.n - 1];
            lanes[i].take(last, last.code, c.n > 1 ? c[c.n - 2].f : lanes[i].f_, c.n > 1 ? c[c.n - 2].p : lanes[i].p_);
        }
    }

    const Codebook& cb_;
    const float step_, step2_, two_step_;
    const std::size_t depth_;
    const LookaheadRivals rivals_;
    RowFrame f_;  // the decoder's state before point k_
    F4 p_;
    std::span<const Vec3f> targets_, alt_;
    Code* codes_ = nullptr;
    Vec3f* decoded_ = nullptr;
    std::size_t k_ = 0;
    Chain chains_[2];
    Chain *chain_ = nullptr, *trial_ = nullptr;  // the best path so far, a rival's being tried
};

// Greedy aiming for N blocks of `m` codes each, in lockstep: the blocks are
// independent, so the N dependency chains (frame -> aim -> code -> frame)
// overlap in the CPU's pipelines. Same result as search_codes with beam 1.
template <class Codebook, int N>
struct GreedyLanes {
    Frame f[N];
    Vec3f p[N];
    const Vec3f* targets[N];
    typename Codebook::Code* codes[N];
    Vec3f* decoded[N];

    void run(const Codebook& cb, float step, std::size_t m) {
        for (std::size_t k = 0; k < m; ++k) {
            typename Codebook::Code code[N];
            for (int i = 0; i < N; ++i) code[i] = cb.nearest(apply_transposed(f[i], targets[i][k] - p[i]));
            for (int i = 0; i < N; ++i) {
                codes[i][k] = code[i];
                f[i] = compose(f[i], cb.frame(code[i]));
                p[i] = p[i] + step * f[i].c[0];
                decoded[i][k] = p[i];
            }
        }
    }
};

}  // namespace fiblet::detail
