// The "lanes" decoder: one block per SIMD lane, W blocks at a time, each
// decoded sequentially. Every lane performs the reference decoder's float
// operations in the reference's order (separate multiplies and adds, never
// fused: the library is built with -ffp-contract=off), so the points are
// bit-identical to decode_blocks_scalar's (decode_blocks_scalar16's for
// 16-bit blocks: one kernel, templated on the block layout).
//
// Per step the W lanes look their local frame up (V::lookup: W row loads
// and a transpose), compose it into their frame, advance and convert to
// world coordinates. Points are staged as rows (x, y, z of point i for all
// lanes) and every W points three W x W transposes turn 3W rows into each
// lane's 3W consecutive output floats, written with (masked) vector stores.
// Included by decode_{portable,avx2,avx512}.cpp after the definition of V.

namespace lanes {

struct Vec {
    V::F x, y, z;
};
inline V::F dot(const Vec& a, const Vec& b) {
    return V::add(V::add(V::mul(a.x, b.x), V::mul(a.y, b.y)), V::mul(a.z, b.z));
}
inline Vec cross(const Vec& a, const Vec& b) {
    return {V::sub(V::mul(a.y, b.z), V::mul(a.z, b.y)), V::sub(V::mul(a.z, b.x), V::mul(a.x, b.z)),
            V::sub(V::mul(a.x, b.y), V::mul(a.y, b.x))};
}
inline Vec scale(V::F s, const Vec& a) { return {V::mul(s, a.x), V::mul(s, a.y), V::mul(s, a.z)}; }
inline Vec normalize(const Vec& a) { return scale(V::div(V::set1(1.0f), V::sqrt(dot(a, a))), a); }
inline Vec select(V::M m, const Vec& a, const Vec& b) {
    return {V::select(m, a.x, b.x), V::select(m, a.y, b.y), V::select(m, a.z, b.z)};
}

// block_start() for W blocks at once: the anchors from their unorm words
// (`words[k][lane]`, as floats, exact) and the first frame. Operation for
// operation the scalar anchor_axis() (core/block_geometry.hpp), or for
// packed 16-bit blocks packed16_anchor_axis() (the words' difference), and
// frame_from_axis() (encode/direction_code.cpp), so the frames are
// bit-identical (the lanes equivalence tests fail if they part).
inline void block_starts(const float (&words)[6][V::W], float unorm_max, bool axis_from_words, Vec& a0, Vec& a1,
                         V::F (&frame)[9]) {
    const V::F unorm = V::set1(unorm_max);
    a0 = {V::div(V::load(words[0]), unorm), V::div(V::load(words[1]), unorm), V::div(V::load(words[2]), unorm)};
    a1 = {V::div(V::load(words[3]), unorm), V::div(V::load(words[4]), unorm), V::div(V::load(words[5]), unorm)};
    const V::F zero = V::set1(0.0f), one = V::set1(1.0f);
    const Vec d = axis_from_words ? Vec{V::sub(V::load(words[3]), V::load(words[0])), V::sub(V::load(words[4]), V::load(words[1])),
                                        V::sub(V::load(words[5]), V::load(words[2]))}
                                  : Vec{V::sub(a1.x, a0.x), V::sub(a1.y, a0.y), V::sub(a1.z, a0.z)};
    const V::F n2 = dot(d, d);
    const Vec axis = select(V::less(zero, n2), scale(V::div(one, V::sqrt(n2)), d), Vec{one, zero, zero});
    const Vec helper{V::set1(kFrameHelper[0]), V::set1(kFrameHelper[1]), V::set1(kFrameHelper[2])};
    const Vec other{zero, helper.z, V::set1(-kFrameHelper[1])};
    Vec c1 = cross(axis, helper);
    c1 = select(V::less(dot(c1, c1), V::set1(1e-6f)), cross(axis, other), c1);
    c1 = normalize(c1);
    const Vec c2 = normalize(cross(axis, c1));
    const V::F f[9] = {axis.x, axis.y, axis.z, c1.x, c1.y, c1.z, c2.x, c2.y, c2.z};
    for (int c = 0; c < 9; ++c) frame[c] = f[c];
}

// The two block layouts: where the anchors, point count and codes are.
struct Blocks8 {
    using Code = Code8;
    static constexpr int kCodesOffset = kBlockDirectionsOffset, kCodeBytes = 1;
    static constexpr bool kGroupByLength = false;  // 97 % of lane steps work in block order
    static int points(const std::uint8_t* b) { return int(BlockView{b}.point_count()); }
    static void anchor_words(const std::uint8_t* b, float* w) {
        const auto q = BlockView{b}.anchor_words();
        for (int k = 0; k < 6; ++k) w[k] = float(q[k]);
    }
};
struct Blocks16 {
    using Code = Code16;
    static constexpr int kCodesOffset = kBlock16DirectionsOffset, kCodeBytes = 2;
    static constexpr bool kGroupByLength = true;  // 87 % in block order (order_by_points)
    static int points(const std::uint8_t* b) { return int(BlockView16{b}.point_count()); }
    static void anchor_words(const std::uint8_t* b, float* w) {
        for (int k = 0; k < 6; ++k) w[k] = float(BlockView16{b}.anchor_word(k));  // < 2^24: exact
    }
};

// The lanes of a group walk until its longest block ends, so long blocks
// are grouped by point count (a stable counting sort, longest first): on
// the medium tractogram's 254-point blocks 87 % of the lane steps did work
// in block order, ~100 % grouped (the decode 6 % faster). The points still
// go where the block order puts them (`first_float`).
template <class Blocks>
void order_by_points(const std::uint8_t* blocks, std::size_t count, int bb, std::vector<std::uint32_t>& order,
                     std::vector<std::size_t>& first_float) {
    std::vector<std::uint32_t> start;  // per point count, longest first
    first_float.resize(count);
    std::size_t floats = 0;
    for (std::size_t b = 0; b < count; ++b) {
        const int n = Blocks::points(blocks + b * std::size_t(bb));
        if (std::size_t(n) >= start.size()) start.resize(std::size_t(n) + 1);
        ++start[std::size_t(n)];
        first_float[b] = floats;
        floats += 3 * std::size_t(n);
    }
    std::uint32_t at = 0;
    for (std::size_t n = start.size(); n-- > 0;) at += std::exchange(start[n], at);
    order.resize(count);
    for (std::size_t b = 0; b < count; ++b)
        order[start[std::size_t(Blocks::points(blocks + b * std::size_t(bb)))]++] = std::uint32_t(b);
}

}  // namespace lanes

// Over 80 lines with a reason: one SIMD kernel whose lane state (a frame
// and point per block, 16 blocks a vector) stays in registers from the
// anchors through the walk to the stores.
template <class Blocks>
// NOLINTNEXTLINE(readability-function-size): the reason above
std::size_t decode_lanes_of(const DecodeContext& ctx, const float* rows_table, float unorm_max, bool axis_from_words,
                            const std::uint8_t* blocks, std::size_t count, float* xyz) {
    using F = V::F;
    constexpr int W = V::W;
    const FftHeader& h = ctx.header;
    const int bb = int(h.block_bytes());
    const F step = V::set1(h.step), half = V::set1(0.5f), scaling = V::set1(h.scaling);
    const F offset[3] = {V::set1(h.offset[0]), V::set1(h.offset[1]), V::set1(h.offset[2])};

    std::vector<std::uint32_t> order;
    std::vector<std::size_t> first_float;
    if constexpr (Blocks::kGroupByLength) lanes::order_by_points<Blocks>(blocks, count, bb, order, first_float);

    // Per lane: the six unorm16 anchor coordinates, as floats.
    alignas(64) float words[6][W];
    // Blocks in order are read with a stride (fewer registers in the walk):
    // the last group's is padded.
    std::vector<std::uint8_t> padded;
    alignas(64) float rows[3 * W][W];
    const std::uint8_t* lane_block[W];
    float* dst[W];
    int lane_floats[W];

    std::size_t floats = 0;
    for (std::size_t g = 0; g < count; g += W) {
        // The last group's missing lanes repeat its last block (and write nothing).
        const int m = int(std::min<std::size_t>(W, count - g));
        const std::uint8_t* base = blocks + g * std::size_t(bb);
        if (!Blocks::kGroupByLength && m < W) {
            padded.resize(std::size_t(W) * bb);
            for (int l = 0; l < W; ++l)
                std::memcpy(&padded[std::size_t(l) * bb], base + std::size_t(std::min(l, m - 1)) * bb, bb);
            base = padded.data();
        }
        int max_points = 0, min_floats = std::numeric_limits<int>::max();
        for (int l = 0; l < W; ++l) {
            std::size_t b = g + std::size_t(std::min(l, m - 1));
            if constexpr (Blocks::kGroupByLength) b = order[b];
            const std::uint8_t* block = lane_block[l] =
                Blocks::kGroupByLength ? blocks + b * std::size_t(bb) : base + std::size_t(l) * bb;
            float w[6];
            Blocks::anchor_words(block, w);
            for (int k = 0; k < 6; ++k) words[k][l] = w[k];
            const int n = l < m ? Blocks::points(block) : 0;
            dst[l] = xyz + (Blocks::kGroupByLength ? first_float[b] : floats);
            lane_floats[l] = 3 * n;
            floats += std::size_t(3 * n);
            max_points = std::max(max_points, n);
            min_floats = std::min(min_floats, 3 * n);
        }
        lanes::Vec a0, a1;
        F frame[9];  // component 3 col + row
        lanes::block_starts(words, unorm_max, axis_from_words, a0, a1, frame);

        // Rows 3(i % W) + c hold component c of point i. After point
        // `first + W - 1` (or the last point), rows q W .. q W + W - 1
        // transposed are the floats 3 first + q W .. + W of every lane.
        auto flush = [&](int first) {
            for (int q = 0; q < 3; ++q) {
                F t[W];
                for (int j = 0; j < W; ++j) t[j] = V::load(rows[q * W + j]);
                V::transpose(t);
                const int at = 3 * first + q * W;
                if (at + W <= min_floats) {  // every lane has all W floats
                    for (int l = 0; l < W; ++l) V::storeu(dst[l] + at, t[l]);
                } else {
                    for (int l = 0; l < W; ++l) {
                        const int k = std::min(lane_floats[l] - at, W);
                        if (k > 0) V::store_n(dst[l] + at, t[l], k);
                    }
                }
            }
        };
        auto emit = [&](int i, F x, F y, F z) {
            const int r = 3 * (i % W);
            V::store(rows[r], V::sub(V::mul(V::sub(x, half), scaling), offset[0]));
            V::store(rows[r + 1], V::sub(V::mul(V::sub(y, half), scaling), offset[1]));
            V::store(rows[r + 2], V::sub(V::mul(V::sub(z, half), scaling), offset[2]));
            if (i % W == W - 1 || i == max_points - 1) flush(i - i % W);
        };

        emit(0, a0.x, a0.y, a0.z);
        F p[3] = {a1.x, a1.y, a1.z};
        if (max_points >= 2) emit(1, p[0], p[1], p[2]);

        const std::uint8_t* codes[W];
        for (int l = 0; l < W; ++l) codes[l] = lane_block[l] + Blocks::kCodesOffset;
        for (int k = 0; k + 2 < max_points; ++k) {
            // 16-bit codes: their frame rows (4 MiB) are not in cache; ask
            // for those of a later step while this one computes. No bits
            // change. Codes past a lane's points are still its block's bytes.
            if constexpr (Blocks::kCodeBytes == 2) {
                constexpr int kAhead = 6;
                if (k + kAhead + 2 < max_points)
                    for (int l = 0; l < W; ++l)
                        __builtin_prefetch(rows_table + 16 * std::size_t(Code16::at(codes[l] + 2 * (k + kAhead))));
            }
            F local[9];
            using Code = typename Blocks::Code;
            const int at = Blocks::kCodeBytes * k;
            if constexpr (Blocks::kGroupByLength)
                V::template lookup<Code>(rows_table, [&](int j) { return codes[j] + at; }, local);
            else
                V::template lookup<Code>(rows_table, [&](int j) { return codes[0] + j * bb + at; }, local);
            // frame = frame * local, as compose(): column j = F * local.c[j],
            // summed left to right.
            F next[9];
            for (int j = 0; j < 3; ++j)
                for (int r = 0; r < 3; ++r)
                    next[3 * j + r] = V::add(V::add(V::mul(frame[r], local[3 * j]), V::mul(frame[3 + r], local[3 * j + 1])),
                                             V::mul(frame[6 + r], local[3 * j + 2]));
            for (int c = 0; c < 9; ++c) frame[c] = next[c];
            for (int r = 0; r < 3; ++r) p[r] = V::add(p[r], V::mul(step, frame[r]));
            emit(k + 2, p[0], p[1], p[2]);
        }
    }
    return floats / 3;
}

inline std::size_t decode_lanes(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count, float* xyz) {
    return decode_lanes_of<lanes::Blocks8>(ctx, ctx.frame_rows.data(), 65535.0f, false, blocks, count, xyz);
}

// 16-bit blocks (formats/fft16.md): unorm24 anchors, u16 codes; version 17
// (packed) takes its first axis from the anchors' integers.
inline std::size_t decode_lanes16(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count, float* xyz) {
    return decode_lanes_of<lanes::Blocks16>(ctx, ctx.frame_rows16->rows.data(), float(kUnorm24Max), ctx.header.packed(),
                                            blocks, count, xyz);
}
