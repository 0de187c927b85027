// Internal: the code search's per-step operations with one block per SIMD
// lane, for the Highway kernels (greedy_blocks.cpp, lookahead_blocks.cpp).
//
// Highway's per-target header pattern: included once per target from a
// file that includes hwy/foreach_target.h, inside its target check (SSE4,
// AVX2 and AVX3 only). Each operation repeats the scalar search's float
// operations in the same order (row_frame.hpp, NearestCodeLut::operator(),
// the library builds with -ffp-contract=off: no fused multiply-add), so
// every lane gets the scalar search's bits.
#if defined(FIBLET_CODE_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef FIBLET_CODE_LANES_INL_H_
#undef FIBLET_CODE_LANES_INL_H_
#else
#define FIBLET_CODE_LANES_INL_H_
#endif

#include <hwy/highway.h>

#include <algorithm>
#include <cstdint>

#include "encode/code_search.hpp"
#include "encode/greedy_blocks.hpp"

HWY_BEFORE_NAMESPACE();
namespace fiblet::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

constexpr std::size_t kMaxLanes = 16;

// out[i] = base[at + i] per lane, i < n (at: float indices). Pairs of
// neighbouring floats come with one 64-bit gather per eight lanes (AVX-512;
// per four with AVX2), then a permutation per float: gathers cost per
// element fetched (on AMD Zen 4, 6.1 ns for sixteen floats against 3.8 ns
// for eight pairs): the targets' three floats and the retry's rival
// records (table records come by rows: LoadRecords). The same floats as one
// gather each, so the same bits at every level.
template <class D>
HWY_INLINE void GatherFloats(D d, const float* base, hn::Vec<hn::RebindToSigned<D>> at, hn::Vec<D>* out, int n) {
    int i = 0;
#if HWY_TARGET == HWY_AVX3
    if constexpr (hn::MaxLanes(D()) == 16) {
        const __m256i lo_at = _mm512_castsi512_si256(at.raw), hi_at = _mm512_extracti64x4_epi64(at.raw, 1);
        const __m512i firsts = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
        const __m512i seconds = _mm512_add_epi32(firsts, _mm512_set1_epi32(1));
        for (; i + 2 <= n; i += 2) {
            const __m512 lo = _mm512_castpd_ps(_mm512_i32gather_pd(lo_at, base + i, 4));
            const __m512 hi = _mm512_castpd_ps(_mm512_i32gather_pd(hi_at, base + i, 4));
            out[i].raw = _mm512_permutex2var_ps(lo, firsts, hi);
            out[i + 1].raw = _mm512_permutex2var_ps(lo, seconds, hi);
        }
    }
#endif
#if HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX2
    if constexpr (hn::MaxLanes(D()) == 8) {  // the same with four pairs a gather
        const __m128i lo_at = _mm256_castsi256_si128(at.raw), hi_at = _mm256_extracti128_si256(at.raw, 1);
        for (; i + 2 <= n; i += 2) {
            const __m256 lo = _mm256_castpd_ps(_mm256_i32gather_pd(reinterpret_cast<const double*>(base + i), lo_at, 4));
            const __m256 hi = _mm256_castpd_ps(_mm256_i32gather_pd(reinterpret_cast<const double*>(base + i), hi_at, 4));
            // Per 128-bit half: first floats of lo's pairs, then hi's (lanes 0 1 4 5, 2 3 6 7), put in order.
            out[i].raw = _mm256_castpd_ps(
                _mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(lo, hi, _MM_SHUFFLE(2, 0, 2, 0))), 0b11011000));
            out[i + 1].raw = _mm256_castpd_ps(
                _mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(lo, hi, _MM_SHUFFLE(3, 1, 3, 1))), 0b11011000));
        }
    }
#endif
    for (; i < n; ++i) out[i] = hn::GatherIndex(d, base + i, at);
}

// out[i] = base[at[i] + j] per lane, i < n, for records in a table (at:
// float indices): in vectors of four, eight (AVX2, AVX-512) or sixteen
// lanes (AVX-512), each lane's record comes with plain 128-bit loads and
// the rows are transposed in registers, since AMD's gathers cost per
// element (a frame's nine floats for eight lanes: ~13 ns by rows against
// ~21 ns by pair gathers on this project's AVX2 EPYC VMs). The same floats,
// so the same bits, as GatherFloats. The lanes' indices are stored and read
// back as scalars (taking them out of the register by moves and extracts
// measured 7 % slower for the eight- and sixteen-lane lookahead). Reads the
// record's floats up to at[i] + 3 (n <= 4), + 7 (n <= 8) or + 8 (n == 9):
// the caller's records must have them.
#if HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3
// Rows r0..r3 in the low halves and r4..r7 in the high halves of y[0..3]:
// column c of the 4x4 blocks into col[c] (lane i: row i's float c).
HWY_INLINE void TransposeHalves(const __m256 y[4], __m256 col[4]) {
    const __m256 t0 = _mm256_unpacklo_ps(y[0], y[1]), t1 = _mm256_unpackhi_ps(y[0], y[1]);
    const __m256 t2 = _mm256_unpacklo_ps(y[2], y[3]), t3 = _mm256_unpackhi_ps(y[2], y[3]);
    col[0] = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));
    col[1] = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
    col[2] = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
    col[3] = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
}

// Four floats of lanes i and i + 4's records, from float `from` on.
HWY_INLINE __m256 RowPair(const float* const rec[8], int i, int from) {
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(rec[i] + from)), _mm_loadu_ps(rec[i + 4] + from), 1);
}

// Eight lanes: the records' first n floats (n <= 9) as columns (out[c].raw).
template <class V>
HWY_INLINE void LoadRecords8(const float* base, __m256i at, V* out, int n) {
    alignas(32) std::int32_t index[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(index), at);
    const float* rec[8];
    for (int i = 0; i < 8; ++i) rec[i] = base + index[i];
    for (int from = 0; from < std::min(n, 8); from += 4) {
        __m256 y[4], col[4];
        for (int i = 0; i < 4; ++i) y[i] = RowPair(rec, i, from);
        TransposeHalves(y, col);
        for (int c = 0; c < 4 && from + c < n; ++c) out[from + c].raw = col[c];
    }
    if (n == 9) {  // float 8: the last of floats 5..8
        __m256 y[4];
        for (int i = 0; i < 4; ++i) y[i] = RowPair(rec, i, 5);
        const __m256 t1 = _mm256_unpackhi_ps(y[0], y[1]), t3 = _mm256_unpackhi_ps(y[2], y[3]);
        out[8].raw = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
    }
}
#endif

#if HWY_TARGET == HWY_AVX3
// Sixteen lanes: the records' first n floats (n <= 9) as columns. Each
// vector takes the rows of lanes i, i + 4, i + 8 and i + 12 in its four
// 128-bit quarters; a 4x4 transpose within the quarters puts lanes
// 4q .. 4q + 3 in quarter q, in order.
template <class V>
HWY_INLINE void LoadRecords16(const float* base, __m512i at, V* out, int n) {
    alignas(64) std::int32_t index[16];
    _mm512_store_si512(index, at);
    const float* rec[16];
    for (int i = 0; i < 16; ++i) rec[i] = base + index[i];
    auto rows = [&](int i, int from) {
        __m512 v = _mm512_castps128_ps512(_mm_loadu_ps(rec[i] + from));
        v = _mm512_insertf32x4(v, _mm_loadu_ps(rec[i + 4] + from), 1);
        v = _mm512_insertf32x4(v, _mm_loadu_ps(rec[i + 8] + from), 2);
        return _mm512_insertf32x4(v, _mm_loadu_ps(rec[i + 12] + from), 3);
    };
    for (int from = 0; from < std::min(n, 8); from += 4) {
        __m512 y[4];
        for (int i = 0; i < 4; ++i) y[i] = rows(i, from);
        const __m512 t0 = _mm512_unpacklo_ps(y[0], y[1]), t1 = _mm512_unpackhi_ps(y[0], y[1]);
        const __m512 t2 = _mm512_unpacklo_ps(y[2], y[3]), t3 = _mm512_unpackhi_ps(y[2], y[3]);
        const __m512 col[4] = {_mm512_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0)), _mm512_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2)),
                               _mm512_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0)), _mm512_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2))};
        for (int c = 0; c < 4 && from + c < n; ++c) out[from + c].raw = col[c];
    }
    if (n == 9) {  // float 8: the last of floats 5..8
        __m512 y[4];
        for (int i = 0; i < 4; ++i) y[i] = rows(i, 5);
        const __m512 t1 = _mm512_unpackhi_ps(y[0], y[1]), t3 = _mm512_unpackhi_ps(y[2], y[3]);
        out[8].raw = _mm512_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
    }
}
#endif

// Four lanes: the records' first n floats (n <= 9) as columns (out[c].raw).
template <class V>
HWY_INLINE void LoadRecords4(const float* base, __m128i at, V* out, int n) {
    alignas(16) std::int32_t index[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(index), at);
    const float* rec[4] = {base + index[0], base + index[1], base + index[2], base + index[3]};
    auto transpose = [&](int from, int first, int count) {
        __m128 y[4];
        for (int i = 0; i < 4; ++i) y[i] = _mm_loadu_ps(rec[i] + from);
        const __m128 t0 = _mm_unpacklo_ps(y[0], y[1]), t1 = _mm_unpackhi_ps(y[0], y[1]);
        const __m128 t2 = _mm_unpacklo_ps(y[2], y[3]), t3 = _mm_unpackhi_ps(y[2], y[3]);
        const __m128 col[4] = {_mm_movelh_ps(t0, t2), _mm_movehl_ps(t2, t0), _mm_movelh_ps(t1, t3), _mm_movehl_ps(t3, t1)};
        for (int c = first; c < first + count; ++c) out[from + c].raw = col[c];
    };
    for (int from = 0; from < std::min(n, 8); from += 4) transpose(from, 0, std::min(4, n - from));
    if (n == 9) transpose(5, 3, 1);  // float 8: the last of floats 5..8
}

template <class D>
HWY_INLINE void LoadRecords(D, const float* base, hn::Vec<hn::RebindToSigned<D>> at, hn::Vec<D>* out, int n) {
    if constexpr (hn::MaxLanes(D()) == 4) return LoadRecords4(base, at.raw, out, n);
#if HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3
    else if constexpr (hn::MaxLanes(D()) == 8) return LoadRecords8(base, at.raw, out, n);
#endif
#if HWY_TARGET == HWY_AVX3
    else if constexpr (hn::MaxLanes(D()) == 16) return LoadRecords16(base, at.raw, out, n);
#endif
    else static_assert(hn::MaxLanes(D()) == 4, "the lanes come in vectors of 4, 8 (AVX2, AVX-512) or 16 (AVX-512)");
}

// Float to int32 by truncation, for lanes known to be in int range.
HWY_INLINE __m128i TruncateInRange(__m128 v) { return _mm_cvttps_epi32(v); }
#if HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3
HWY_INLINE __m256i TruncateInRange(__m256 v) { return _mm256_cvttps_epi32(v); }
#endif
#if HWY_TARGET == HWY_AVX3
HWY_INLINE __m512i TruncateInRange(__m512 v) { return _mm512_cvttps_epi32(v); }
#endif

// The 8-bit code book, one code per lane. A frame is held as nine vectors,
// f[3 * c + i] = component i of column c (column 0: the step's direction).
// Frames and directions come by LoadRecords (rows: the default's encode
// stage 5-7 % faster than by pair gathers at AVX2 and AVX-512 on an AMD Zen 4
// VM; greedy aiming's BM_EncodeSearch 35.4 -> 32.4 ms on a Zen 3 AVX2 VM).
// frame() and direction() are inlined: GCC outlined them with rows, each
// call spilling the live vectors (which hid the rows' gain in the lookahead).
template <class D>
struct CodeLanes {
    using DI = hn::RebindToSigned<D>;
    using VF = hn::Vec<D>;
    using VI = hn::Vec<DI>;
    static_assert(sizeof(Frame) == 9 * sizeof(float), "frames are gathered as 9 floats");

    D d;
    DI di;
    const float* code_frames;
    NearestCodeLut::Gnomonic g;
    VF zero, one, rim_tan, rim_tan2, cell_scale, last_cell, int_range;
    VI zero_word, back_word, low16, byte;

    explicit CodeLanes(const Codebook8& cb)
        : code_frames(&cb.table.frame(0).c[0].x), g(cb.lut.gnomonic()), zero(hn::Zero(d)), one(hn::Set(d, 1.0f)),
          rim_tan(hn::Set(d, g.rim_tan)), rim_tan2(hn::Set(d, g.rim_tan2)), cell_scale(hn::Set(d, g.cell_scale)),
          last_cell(hn::Set(d, float(NearestCodeLut::kGrid - 1))), int_range(hn::Set(d, 2147483648.0f)),
          zero_word(hn::Set(di, g.zero_word)), back_word(hn::Set(di, g.back_word)), low16(hn::Set(di, 0xffff)),
          byte(hn::Set(di, 0xff)) {}

    // apply_transposed(f, v): dot(c_j, v) = (c_j.x v.x + c_j.y v.y) + c_j.z v.z.
    static void local(const VF* f, VF vx, VF vy, VF vz, VF& x, VF& y, VF& z) {
        auto dot_v = [&](int c) {
            return hn::Add(hn::Add(hn::Mul(f[3 * c], vx), hn::Mul(f[3 * c + 1], vy)), hn::Mul(f[3 * c + 2], vz));
        };
        x = dot_v(0), y = dot_v(1), z = dot_v(2);
    }

    // NearestCodeLut::cell(): int((u + rim_tan) * cell_scale) clamped to [0, kGrid - 1].
    // The scalar conversion (cvttss2si) gives INT_MIN for NaN and for values
    // out of int range, which the clamp turns into 0; Highway's saturates
    // instead, so those lanes are zeroed before converting.
    VI cell(VF u) const {
        const VF f = hn::Mul(hn::Add(u, rim_tan), cell_scale);
        const VF in_range = hn::IfThenElseZero(hn::Lt(f, int_range), f);  // NaN, >= 2^31: 0
        VI out;  // the truncation alone: Highway's ConvertTo adds a fix-up for lanes out of int range, which the clamp rules out
        out.raw = TruncateInRange(hn::Min(hn::Max(in_range, zero), last_cell).raw);
        return out;
    }

    // NearestCodeLut::aim(local) as its cell's word, code | rival << 8:
    // both the cap's and the rim's (u, v), then per lane the one it takes.
    VI aim(VF x, VF y, VF z) const {
        const VF lateral2 = hn::Add(hn::Mul(y, y), hn::Mul(z, z));
        const auto in_cap = hn::And(hn::Gt(x, zero), hn::Le(lateral2, hn::Mul(rim_tan2, hn::Mul(x, x))));
        const VF inv = hn::Div(one, x);
        VF u = hn::Mul(y, inv), v = hn::Mul(z, inv);
        // The rim's square root and division only when a lane needs them
        // (rare: they would lengthen every step's dependency chain).
        if (!hn::AllTrue(d, in_cap)) {
            const VF s = hn::Div(rim_tan, hn::Sqrt(lateral2));
            u = hn::IfThenElse(in_cap, u, hn::Mul(y, s));
            v = hn::IfThenElse(in_cap, v, hn::Mul(z, s));
        }
        const VI index = hn::Add(hn::ShiftLeft<8>(cell(u)), cell(v));
        // The cell's 16 bits: a 32-bit gather of its pair of cells (cells
        // 2i and 2i + 1; the table's count is even), then the half it is.
        const VI pair = hn::GatherIndex(di, reinterpret_cast<const std::int32_t*>(g.cells), hn::ShiftRight<1>(index));
        const VI looked_up = hn::And(pair >> hn::ShiftLeft<4>(hn::And(index, hn::Set(di, 1))), low16);
        // Outside the cap with no lateral direction: straight back or the zero vector's word.
        const auto no_lateral = hn::RebindMask(di, hn::AndNot(in_cap, hn::Not(hn::Gt(lateral2, zero))));
        const VI behind = hn::IfThenElse(hn::RebindMask(di, hn::Lt(x, zero)), back_word, zero_word);
        return hn::IfThenElse(no_lateral, behind, looked_up);
    }
    // NearestCodeLut::operator()(local).
    VI nearest(VF x, VF y, VF z) const { return code_of(aim(x, y, z)); }
    // An aim word's code and rival.
    VI code_of(VI word) const { return hn::And(word, byte); }
    static VI rival_of(VI word) { return hn::ShiftRight<8>(word); }

    // Where the code's frame starts in the table, in floats: code * 9.
    static VI frame_at(VI code) { return hn::Add(hn::ShiftLeft<3>(code), code); }

    // The code's frame (its first column is its direction).
    HWY_INLINE void frame(VI code, VF* l) const {
        const VI at = frame_at(code);
        LoadRecords(d, code_frames, at, l, 9);
    }

    // The code's direction (its frame's first column).
    HWY_INLINE void direction(VI code, VF& x, VF& y, VF& z) const {
        const VI at = frame_at(code);
        VF v[3];
        LoadRecords(d, code_frames, at, v, 3);
        x = v[0], y = v[1], z = v[2];
    }

    // compose(f, l): column c of the result is apply(f, l.c_c) =
    // (f.c0 l.x + f.c1 l.y) + f.c2 l.z, per component.
    static void compose(const VF* f, const VF* l, VF* out) {
        for (int c = 0; c < 3; ++c)
            for (int i = 0; i < 3; ++i)
                out[3 * c + i] =
                    hn::Add(hn::Add(hn::Mul(f[i], l[3 * c]), hn::Mul(f[3 + i], l[3 * c + 1])), hn::Mul(f[6 + i], l[3 * c + 2]));
    }
};

// Blocks j0 .. j0 + active - 1 of a batch, one per lane of `d` (lanes past
// `active` repeat the last block; their results are dropped): the decoder's
// state (frame f, point p), where each lane's next target is, and where its
// results go.
template <class D>
struct BatchLanes {
    using VF = hn::Vec<D>;
    using VI = hn::Vec<hn::RebindToSigned<D>>;
    static_assert(sizeof(Vec3f) == 3 * sizeof(float), "points are gathered as 3 floats");

    D d;
    VF f[9], px, py, pz;
    // Lane i's target k at float index first_at[i] + 3 k (relative to block
    // j0's targets), held at its last target once its block is done (a
    // shorter last block).
    VI at, at_end, lengths;  // lengths: m_of
    const float* targets;
    // Zeroed past the vector's lanes (GCC cannot tell that store() reads only active ones).
    std::size_t m_of[kMaxLanes] = {}, steps = 0, active;
    Vec3f* decoded[kMaxLanes] = {};
    std::uint8_t* codes[kMaxLanes] = {};

    BatchLanes(const GreedyBatch& batch, std::size_t j0, std::size_t n) : targets(&batch.targets[j0 * batch.stride].x), active(std::min(n, hn::Lanes(D()))) {
        const hn::RebindToSigned<D> di;
        alignas(64) float start[12][kMaxLanes];
        alignas(64) std::int32_t first_at[kMaxLanes], last_at[kMaxLanes], length[kMaxLanes];
        for (std::size_t i = 0; i < hn::Lanes(d); ++i) {
            const std::size_t j = j0 + std::min(i, active - 1);
            const Frame& fr = batch.frames[j];
            const Vec3f& p = batch.starts[j * batch.stride];
            for (int c = 0; c < 3; ++c)
                start[3 * c][i] = fr.c[c].x, start[3 * c + 1][i] = fr.c[c].y, start[3 * c + 2][i] = fr.c[c].z;
            start[9][i] = p.x, start[10][i] = p.y, start[11][i] = p.z;
            m_of[i] = batch.length(j);
            length[i] = std::int32_t(m_of[i]);
            steps = std::max(steps, m_of[i]);
            first_at[i] = std::int32_t(3 * (j - j0) * batch.stride);
            last_at[i] = std::int32_t(3 * ((j - j0) * batch.stride + m_of[i] - 1));
        }
        for (int j = 0; j < 9; ++j) f[j] = hn::Load(d, start[j]);
        px = hn::Load(d, start[9]), py = hn::Load(d, start[10]), pz = hn::Load(d, start[11]);
        at = hn::Load(di, first_at), at_end = hn::Load(di, last_at), lengths = hn::Load(di, length);
        for (std::size_t i = 0; i < active; ++i)
            decoded[i] = batch.decoded + (j0 + i) * batch.stride, codes[i] = batch.codes + (j0 + i) * batch.code_stride;
    }

    // The lanes' targets at `where`.
    void target(VI where, VF& x, VF& y, VF& z) const {
        VF v[3];
        GatherFloats(d, targets, where, v, 3);
        x = v[0], y = v[1], z = v[2];
    }
    VI next_at() const { return ahead_at(1); }
    // Where the targets n points ahead are (the last target past a lane's end).
    VI ahead_at(int n) const { return hn::Min(hn::Add(at, hn::Set(hn::RebindToSigned<D>(), 3 * n)), at_end); }
    // Lanes still having a target after step k.
    hn::Mask<D> more_after(std::size_t k) const {
        const hn::RebindToSigned<D> di;
        return hn::RebindMask(d, hn::Lt(hn::Set(di, std::int32_t(k + 1)), lengths));
    }

    // Step k's point and code to each active lane's block (scalar stores,
    // which the CPU overlaps with the next step's dependency chain); on to
    // the next targets.
    void store(std::size_t k, VI code) {
        // Zeroed: a narrower vector stores fewer than kMaxLanes (GCC cannot
        // tell that only those are read).
        alignas(64) float out[3][kMaxLanes] = {};
        alignas(64) std::int32_t out_code[kMaxLanes] = {};
        hn::Store(px, d, out[0]);
        hn::Store(py, d, out[1]);
        hn::Store(pz, d, out[2]);
        hn::Store(code, hn::RebindToSigned<D>(), out_code);
        for (std::size_t i = 0; i < active; ++i) {
            if (k >= m_of[i]) continue;
            decoded[i][k] = {out[0][i], out[1][i], out[2][i]};
            codes[i][k] = std::uint8_t(out_code[i]);
        }
        at = next_at();
    }
};

// Blocks [0, batch.blocks) in vectors of Kernel(d, cb, step, batch, j0,
// active): full ones of the widest width, then the rest in the narrowest
// width that holds it (at least 2 blocks a vector); returns the blocks done
// (the few left are the scalar search's).
template <class Kernel>
std::size_t AllVectors(const Codebook8& cb, float step, const GreedyBatch& batch, Kernel kernel) {
    const hn::ScalableTag<float> d;
    const std::size_t lanes = hn::Lanes(d);
    std::size_t j = 0;
    for (; j + lanes <= batch.blocks; j += lanes) kernel(d, cb, step, batch, j, lanes);
    const std::size_t left = batch.blocks - j;
    if (left < 2) return j;
#if HWY_TARGET == HWY_AVX3
    if (left > 8) kernel(d, cb, step, batch, j, left);
    else if (left > 4) kernel(hn::CappedTag<float, 8>(), cb, step, batch, j, left);
    else kernel(hn::CappedTag<float, 4>(), cb, step, batch, j, left);
#elif HWY_TARGET == HWY_AVX2
    if (left > 4) kernel(d, cb, step, batch, j, left);
    else kernel(hn::CappedTag<float, 4>(), cb, step, batch, j, left);
#else
    kernel(d, cb, step, batch, j, left);
#endif
    return batch.blocks;
}

}  // namespace fiblet::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // FIBLET_CODE_LANES_INL_H_
