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
#include <cstdint>
#include <span>
#include <vector>

#include "codec/nearest_code_lut.hpp"
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

    struct State {
        Frame f;
        Vec3f p;
        float cost;
    };
    struct Candidate {
        float cost;
        std::uint32_t parent;
        std::uint32_t code;
    };
    struct Link {
        std::uint32_t parent;
        std::uint32_t code;
    };
    const unsigned width = sp.beam;
    const int r = int(sp.radius);
    thread_local std::vector<State> states, next;
    thread_local std::vector<Candidate> cand;
    thread_local std::vector<Link> links;  // links[k * width + j]: how state j of step k was reached
    states.assign(1, State{f, p, 0.0f});
    next.resize(width);
    cand.resize(width);
    links.resize(m * width);
    const float step2 = step * step, two_step = 2.0f * step;

    for (std::size_t k = 0; k < m; ++k) {
        // The `width` cheapest candidates, kept sorted by cost (insertion from
        // the end; most candidates are rejected by the first comparison).
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
                    if (kept == width && !(cost < cand[width - 1].cost)) continue;
                    std::size_t i = kept < width ? kept++ : width - 1;
                    for (; i > 0 && cand[i - 1].cost > cost; --i) cand[i] = cand[i - 1];
                    cand[i] = {cost, s, code};
                }
        }
        for (std::size_t j = 0; j < kept; ++j) {
            const Candidate& c = cand[j];
            const State& parent = states[c.parent];
            State& n = next[j];
            n.f = compose(parent.f, cb.frame(c.code));
            n.p = parent.p + step * n.f.c[0];
            n.cost = c.cost;
            links[k * width + j] = {c.parent, c.code};
        }
        next.resize(kept);
        states.swap(next);
        next.resize(width);
    }

    // Back-track the cheapest sequence, then replay it for the decoded points.
    std::uint32_t j = 0;
    for (std::uint32_t s = 1; s < states.size(); ++s)
        if (states[s].cost < states[j].cost) j = s;
    for (std::size_t k = m; k-- > 0;) {
        codes[k] = Code(links[k * width + j].code);
        j = links[k * width + j].parent;
    }
    for (std::size_t k = 0; k < m; ++k) {
        f = compose(f, cb.frame(codes[k]));
        p = p + step * f.c[0];
        decoded[k] = p;
    }
}

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
