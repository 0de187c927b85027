#include <algorithm>
#include <cmath>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "encode/anchor_conditioning.hpp"
#include "encode/code_search.hpp"
#include "encode/exact_model.hpp"
#include "encode/greedy_blocks.hpp"
#include "encode/length_feedback.hpp"
#include "encode/lookahead_blocks.hpp"
#include "encode/nearest_code_lut.hpp"
#include "core/block_geometry.hpp"
#include "core/append_points.hpp"
#include "core/grow.hpp"
#include "core/points_avx2.hpp"
#include "core/vec_math.hpp"
#include "fiblet/encode.hpp"
#include "fiblet/error.hpp"
#include "container/packed_blocks16.hpp"

namespace fiblet {
using namespace detail;

namespace {

// A point's anchor words in normalized coordinates, computed in double so
// that the rounding to the unorm grid (2^16 - 1 or 2^24 - 1 steps) is the
// only loss.
struct Quantized {
    std::uint32_t q[3];
};

Vec3d normalized_point(const FftHeader& h, Vec3f p) {
    return {(double(p.x) + h.offset[0]) / h.scaling + 0.5, (double(p.y) + h.offset[1]) / h.scaling + 0.5,
            (double(p.z) + h.offset[2]) / h.scaling + 0.5};
}

Quantized quantize_point(const FftHeader& h, Vec3f p, double levels) {
    auto one = [&](double v, int axis) {
        const double n = (v + h.offset[axis]) / h.scaling + 0.5;
        return static_cast<std::uint32_t>(std::lround(std::clamp(n, 0.0, 1.0) * levels));
    };
    return {{one(p.x, 0), one(p.y, 1), one(p.z, 2)}};
}

void put_word(std::uint8_t* w, std::uint32_t a, std::uint32_t b) {
    // Version 2 anchor word: a | b << 16, most-significant byte first.
    w[0] = std::uint8_t(b >> 8), w[1] = std::uint8_t(b), w[2] = std::uint8_t(a >> 8), w[3] = std::uint8_t(a);
}

void put_le(std::uint8_t* p, std::uint32_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) p[i] = std::uint8_t(v >> (8 * i));
}

// Blocks whose two decoders may diverge by more than this share of an
// anchor quantum (1/65535) get the robust search. The bound is 0.1 to 0.3
// of a quantum in common blocks (the anchors' float rounding alone) and
// grows as 1 / |F0 x C| where the first segment runs along the helper.
// Measured on small-ifod1 (docs/encode.md): 0.5 brings the exact decode's
// max error from 9.52 to 6.01 um for 1.1x the encode time; 0.2 and 0.05
// lower the max and mean a little more for 1.7x and 4x.
constexpr double kRobustDivergence = 0.5 / 65535.0;

// Writes the anchors, fiber id and flags of 16-bit block b (of n_blocks)
// holding n points; returns where the decoders start (the float anchors).
DecoderStarts write_block_head16(const FftHeader& h, std::uint8_t* block, Vec3f p0, Vec3f p1, std::uint32_t fiber_id,
                                 std::uint32_t b, std::uint32_t n_blocks, std::uint32_t n) {
    const bool first = b == 0, last = b + 1 == n_blocks;
    const Quantized q0 = quantize_point(h, p0, kUnorm24Max), q1 = quantize_point(h, p1, kUnorm24Max);
    for (int i = 0; i < 3; ++i) put_le(block + 3 * i, q0.q[i], 3), put_le(block + 9 + 3 * i, q1.q[i], 3);
    put_le(block + kBlock16FiberIdOffset, fiber_id, 4);
    put_le(block + kBlock16FlagsOffset, (first ? 0u : kFlag16NotFirst) | (last ? 0u : kFlag16NotLast) | n, 2);
    auto decoded = [](const Quantized& q) {
        return Vec3f{unpack_unorm24(q.q[0]), unpack_unorm24(q.q[1]), unpack_unorm24(q.q[2])};
    };
    DecoderStarts s;
    s.a0 = decoded(q0), s.a1 = decoded(q1);
    return s;
}

// The same for an 8-bit block whose anchor words are chosen (condition_anchors).
void write_block_head8(std::uint8_t* block, const AnchorWords& w, std::uint32_t fiber_id, std::uint32_t b,
                       std::uint32_t n_blocks, std::uint32_t n) {
    const bool first = b == 0, last = b + 1 == n_blocks;
    put_word(block + 0, w.a0[0], w.a0[1]);
    put_word(block + 4, w.a0[2], w.a1[0]);
    put_word(block + 8, w.a1[1], w.a1[2]);
    block[12] = std::uint8_t(fiber_id >> 24), block[13] = std::uint8_t(fiber_id >> 16);
    block[14] = std::uint8_t(fiber_id >> 8), block[15] = std::uint8_t(fiber_id);
    block[kBlockFlagsOffset] = std::uint8_t((first ? 0 : kFlagNotFirst) | (last ? 0 : kFlagNotLast) | n);
    block[kBlockIndexOffset] = std::uint8_t(b);  // modulo 256, as the format stores it
}

FrameD frame_to_double(const Frame& f) { return {{to_double(f.c[0]), to_double(f.c[1]), to_double(f.c[2])}}; }

// The exact decoder's targets in the float decoder's terms: the exact decode
// is the float decode moved rigidly (anchor a1 -> exact1, frame -> exact
// frame), so its error at a point is the float point's distance to
// t' = a1 + frame exact_frame^T (t - exact1).
void exact_decoder_targets(const DecoderStarts& s, std::span<const Vec3f> targets, Vec3f* out) {
    const FrameD fd = frame_to_double(s.frame);
    const Vec3d a = to_double(s.a1);
    for (std::size_t k = 0; k < targets.size(); ++k)
        out[k] = to_float(a + apply(fd, apply_transposed(s.exact_frame, to_double(targets[k]) - s.exact1)));
}

// The retry's first try searches a block with at least this many points of
// lookahead before any beam (retry_with_lookahead).
constexpr std::size_t kRetryLookahead = 2;

// Blocks gathered from several fibers into one batch for the SIMD lanes
// (greedy_blocks.hpp's layout: block j's start point, then its targets, at
// points[j * stride]; its codes at codes[j * m]), and their results.
struct BlockBatch {
    std::size_t m = 0, stride = 0, blocks = 0;
    std::vector<Frame> frames;  // grown (grow)
    std::vector<Vec3f> points, decoded;
    std::vector<std::uint8_t> codes;
    std::vector<std::uint32_t> lengths;

    // Room for `count` blocks of at most m codes.
    void reset(std::size_t longest, std::size_t count) {
        m = longest, stride = m + 1, blocks = count;
        grow(frames, count), grow(points, count * stride), grow(decoded, count * stride);
        grow(codes, count * m), grow(lengths, count);
    }
    void set(std::size_t j, const Frame& f, Vec3f start, std::span<const Vec3f> targets) {
        frames[j] = f, points[j * stride] = start, lengths[j] = std::uint32_t(targets.size());
        std::copy(targets.begin(), targets.end(), &points[j * stride + 1]);
    }
    GreedyBatch batch() {
        return {frames.data(), points.data(), points.data() + 1, decoded.data() + 1, stride, codes.data(), m,
                blocks, m, m, lengths.data()};
    }
    const Vec3f* decoded_of(std::size_t j) const { return &decoded[j * stride + 1]; }
    const std::uint8_t* codes_of(std::size_t j) const { return &codes[j * m]; }
};

// Largest squared distance of decoded[k] to targets[k] or alt[k].
float worst_error2(const Vec3f* decoded, const Vec3f* targets, const Vec3f* alt, std::size_t m) {
    float worst = 0;
    for (std::size_t k = 0; k < m; ++k) {
        const Vec3f d = decoded[k] - targets[k], e = decoded[k] - alt[k];
        worst = std::max({worst, dot(d, d), dot(e, e)});
    }
    return worst;
}

}  // namespace

// The per-file code tables: 8-bit table and its lookup, or the 16-bit table.
struct FiberEncoder::Tables {
    std::optional<DirectionTable> table8;
    std::optional<NearestCodeLut> lut8;
    std::optional<DirectionTable16> table16;
    std::optional<ExactDirectionTable> exact8;  // the exact decoder's frames (exact_model.hpp)
    std::optional<ExactDirectionTable16> exact16;
};

float compute_ratio(double scaling_mm, double step_mm, double min_dot) {
    const double e = scaling_mm / 65536.0;
    // A step no longer than the anchor quantization leaves the first axis
    // arbitrary: take the whole sphere.
    if (!(step_mm > 2 * e)) return 2.0f;
    const double a = std::atan(2 * e / (step_mm - 2 * e));
    const double ratio = 1.0 - std::cos(std::acos(std::clamp(min_dot, -1.0, 1.0)) + a);
    return float(std::clamp(ratio, 1e-4, 2.0));
}

SearchOptions search_for_effort(int effort) {
    // Measured on the shared tractograms (docs/encode.md): a radius of 2
    // never changes the result (codes two levels off the aim never make the
    // beam), so every level searches the 3x3 neighbourhood.
    switch (effort) {
        case 0: return {1, 1, 0, 1, 0};    // greedy aiming
        case 1: return {1, 1, 8, 1, 0, 1};  // greedy judged over the next point + a beam of 8 for the worst blocks
        case 2: return {2, 1, 8, 1, 0};
        case 3: return {8, 1, 32, 1, 0};
        case 4: return {16, 1, 64, 1, 0};
        default: throw Error(Errc::invalid_argument, "effort must be in [0, " + std::to_string(kMaxEffort) + "]");
    }
}

FiberEncoder::FiberEncoder(const FftHeader& header, SearchOptions search) : header_(header), search_(search) {
    if (search_.beam_width < 1 || search_.beam_width > 64)
        throw Error(Errc::invalid_argument, "beam width must be in [1, 64]");
    if (search_.radius < 1 || search_.radius > 3) throw Error(Errc::invalid_argument, "search radius must be in [1, 3]");
    if (search_.lookahead > kMaxLookahead)
        throw Error(Errc::invalid_argument, "lookahead must be in [0, " + std::to_string(kMaxLookahead) + "]");
    if (search_.retry_beam_width > 64 || search_.retry_radius < 1 || search_.retry_radius > 3 ||
        !(search_.retry_error_mm >= 0))
        throw Error(Errc::invalid_argument, "retry beam width must be in [0, 64], its radius in [1, 3]");
    tables_ = shared_tables(header_.direction_bits(), header_.ratio, header_.code_levels());
}

// The tables of (bits, ratio, levels), shared by the encoders that use
// them: tuning builds encoders of the same few caps again and again, and
// the 8-bit lookup alone costs about 12 M instructions (small-ifod1's first
// 600 fibers: 14 % of a compress). The last kKept 8-bit tables (about 0.2 MB
// each) stay built; 16-bit ones (7 MB) only while an encoder holds them.
std::shared_ptr<const FiberEncoder::Tables> FiberEncoder::shared_tables(unsigned bits, float ratio, unsigned levels) {
    constexpr std::size_t kKept = 12;
    struct Entry {
        unsigned bits;
        float ratio;
        unsigned levels;
        std::shared_ptr<const Tables> kept;  // 8-bit
        std::weak_ptr<const Tables> tables;
    };
    static std::mutex mutex;
    static std::vector<Entry> cache;  // oldest first
    const std::lock_guard<std::mutex> lock(mutex);
    std::erase_if(cache, [](const Entry& e) { return e.tables.expired(); });
    for (const Entry& e : cache)
        if (e.bits == bits && e.ratio == ratio && e.levels == levels)
            if (auto t = e.tables.lock()) return t;
    auto t = std::make_shared<Tables>();
    if (bits == 16) {
        t->table16.emplace(ratio, levels);
        t->exact16.emplace(ratio, levels);
    } else {
        t->table8.emplace(ratio);
        t->lut8.emplace(*t->table8);
        t->exact8.emplace(ratio);
    }
    const auto kept = std::count_if(cache.begin(), cache.end(), [](const Entry& e) { return e.kept != nullptr; });
    if (bits != 16 && std::size_t(kept) >= kKept)
        std::find_if(cache.begin(), cache.end(), [](const Entry& e) { return e.kept != nullptr; })->kept.reset();
    cache.push_back({bits, ratio, levels, bits == 16 ? nullptr : t, t});
    return t;
}

FiberEncoder FiberEncoder::with_step(float step) const {
    FiberEncoder e = *this;
    e.header_.step = step;
    return e;
}

FiberEncoder FiberEncoder::with_search(const SearchOptions& search) const {
    FiberEncoder e = *this;
    e.search_ = search;
    return e;
}

FiberEncoder FiberEncoder::with_length_feedback(float stretch, bool tails_only) const {
    FiberEncoder e = *this;
    e.length_stretch_ = stretch;
    e.length_tails_only_ = tails_only;
    return e;
}

namespace {

#ifdef FIBLET_POINTS_AVX2
// normalize_points for points [0, k) four at a time (twelve coordinates in
// three vectors, the offsets rotating), returning k: the same double
// operations and rounding, so the same bits.
__attribute__((target("avx2"))) std::size_t normalize_points_avx2(const float* in, float* out, std::size_t n,
                                                                  const double offset[3], double inv_scaling) {
    const __m256d off0 = _mm256_setr_pd(offset[0], offset[1], offset[2], offset[0]);
    const __m256d off1 = _mm256_setr_pd(offset[1], offset[2], offset[0], offset[1]);
    const __m256d off2 = _mm256_setr_pd(offset[2], offset[0], offset[1], offset[2]);
    const __m256d inv = _mm256_set1_pd(inv_scaling), half = _mm256_set1_pd(0.5);
    std::size_t k = 0;
    for (; k + 4 <= n; k += 4) {
        const float* i = in + 3 * k;
        float* o = out + 3 * k;
        const __m256d a = _mm256_cvtps_pd(_mm_loadu_ps(i)), b = _mm256_cvtps_pd(_mm_loadu_ps(i + 4)),
                      c = _mm256_cvtps_pd(_mm_loadu_ps(i + 8));
        _mm_storeu_ps(o, _mm256_cvtpd_ps(_mm256_add_pd(_mm256_mul_pd(_mm256_add_pd(a, off0), inv), half)));
        _mm_storeu_ps(o + 4, _mm256_cvtpd_ps(_mm256_add_pd(_mm256_mul_pd(_mm256_add_pd(b, off1), inv), half)));
        _mm_storeu_ps(o + 8, _mm256_cvtpd_ps(_mm256_add_pd(_mm256_mul_pd(_mm256_add_pd(c, off2), inv), half)));
    }
    return k;
}
#endif

// n points' coordinates (in: x, y, z, x, ...) normalized as the header
// says, (p + offset) / scaling + 0.5 in double, rounded to float (a
// thirtieth of the default's encode stage in SSE2 code, half that in AVX2).
void normalize_points(const FftHeader& header, const float* in, float* out, std::size_t n) {
    const double inv_scaling = 1.0 / double(header.scaling),
                 offset[3] = {header.offset[0], header.offset[1], header.offset[2]};
    std::size_t k = 0;
#ifdef FIBLET_POINTS_AVX2
    if (use_avx2_loops()) k = normalize_points_avx2(in, out, n, offset, inv_scaling);
#endif
    for (; k < n; ++k)
        for (int c = 0; c < 3; ++c) out[3 * k + c] = float((double(in[3 * k + c]) + offset[c]) * inv_scaling + 0.5);
}

}  // namespace

// One fiber being encoded: what the passes of FiberEncoder::encode share.
// Per point: the target and the decoded point (normalized coordinates); per
// block: the first frame and (8-bit) the decoders' starts. Codes go straight
// into the blocks (8-bit) or through `codes16`. The vectors are per-thread
// scratch, reused from fiber to fiber.
struct FiberEncoder::Encoding {
    struct Scratch {
        std::vector<Vec3f> targets, points, retry_points, alt;
        std::vector<Frame> frames;
        std::vector<DecoderStarts> starts;
        std::vector<std::uint16_t> codes16, retry_codes16;
        std::vector<std::uint8_t> retry_codes8;
        std::vector<Vec3d> walked;
        std::vector<double> block_errors;  // append_exact8: each block's largest point error
        std::optional<LengthTails> tails;  // keep_length_tails
        // tail_start's last answer: the state before code j0 of `block`
        // (a block's tries share it: they change its codes from j0 on).
        struct TailStart {
            std::uint32_t block = ~0u;
            std::size_t j0 = 0;
            Frame f;
            Vec3f p;
        } tail_start;
    };

    const FiberEncoder& enc;
    const FftHeader& header;
    std::span<const Vec3f> fiber;
    std::uint32_t fiber_id;
    std::vector<std::uint8_t>& out;
    Scratch& scratch;
    const std::uint32_t points_per_block, block_bytes;
    const std::size_t n_points, base;
    const std::uint32_t n_blocks;
    const bool wide;

    Encoding(const FiberEncoder& e, std::span<const Vec3f> f, std::uint32_t id, std::vector<std::uint8_t>& o,
             Scratch& s)
        : enc(e), header(e.header_), fiber(f), fiber_id(id), out(o), scratch(s),
          points_per_block(header.points_per_block), block_bytes(header.block_bytes()), n_points(f.size()),
          base(o.size()), n_blocks(e.block_count(f.size())), wide(e.tables_->table16.has_value()) {
        out.resize(base + std::size_t(n_blocks) * block_bytes, 0);
        grow(scratch.targets, n_points);  // longer than the fiber after a longer one: targets(), points()
        grow(scratch.points, n_points);
        grow(scratch.frames, n_blocks);
        if (!wide) grow(scratch.starts, n_blocks);
        if (wide) scratch.codes16.assign(n_points, 0);
        if (n_points) normalize_points(header, &fiber[0].x, &scratch.targets[0].x, n_points);
    }

    // The fiber's targets and decoded points (the scratch arrays may be longer).
    std::span<const Vec3f> targets() const { return {scratch.targets.data(), n_points}; }
    std::span<Vec3f> points() { return {scratch.points.data(), n_points}; }

    std::uint32_t block_points(std::uint32_t b) const {
        return std::uint32_t(std::min<std::size_t>(points_per_block, n_points - std::size_t(b) * points_per_block));
    }
    // How far a block of n points reaches from its second anchor (normalized).
    double block_reach(std::uint32_t n) const { return n > 2 ? double(header.step) * double(n - 2) * 1.01 : 0.0; }
    // The codes of block b: points i0 + 2 .. i0 + n.
    std::uint8_t* codes8_of(std::uint32_t b) {
        return &out[base + std::size_t(b) * block_bytes + kBlockDirectionsOffset];
    }
    Codebook8 codebook8() const { return {*enc.tables_->table8, *enc.tables_->lut8}; }
    bool robust(std::uint32_t b) const { return scratch.starts[b].divergence > kRobustDivergence; }
    const SearchOptions& search() const { return enc.search_; }
    Vec3f world(Vec3d p) const {
        return Vec3f{float((p.x - 0.5) * double(header.scaling) - double(header.offset[0])),
                     float((p.y - 0.5) * double(header.scaling) - double(header.offset[1])),
                     float((p.z - 0.5) * double(header.scaling) - double(header.offset[2]))};
    }

    // Block b's codes with the beam search `sp`, into c8 / c16 and `dec`.
    void search_block(std::uint32_t b, const SearchParams& sp, std::uint8_t* c8, std::uint16_t* c16, Vec3f* dec) const {
        const std::size_t i0 = std::size_t(b) * points_per_block;
        const std::span<const Vec3f> t(&scratch.targets[i0 + 2], block_points(b) - 2);
        if (wide)
            search_codes(Codebook16{*enc.tables_->table16}, sp, scratch.frames[b], scratch.points[i0 + 1], header.step,
                         t, c16, dec);
        else
            search_codes(codebook8(), sp, scratch.frames[b], scratch.points[i0 + 1], header.step, t, c8, dec);
    }

    void write_block_heads();
    void write_block_heads8();
    std::pair<Vec3f, Vec3f> anchor_points(std::uint32_t b) const;
    void search_blocks();
    // A block of one of several fibers searched in SIMD lanes.
    struct LaneBlock {
        Encoding* e;
        std::uint32_t b, m;  // the block, its codes
        float worst2 = 0;    // its largest squared error before the search
        void take(const BlockBatch& batch, std::size_t j) const;  // lane j's codes and points into the block
    };
    static BlockBatch& batch_of(std::vector<LaneBlock>& blocks);
    static void search_blocks_together(std::span<Encoding> fibers);
    float retry_threshold2() const;
    static void retry_worst_blocks(std::span<Encoding> fibers);
    static void retry_with_lookahead(std::vector<LaneBlock>& blocks);
    void retry_with_beam(std::uint32_t b, float first);
    void search_robust_blocks();
    void keep_lengths();
    static void keep_length_tails(std::span<Encoding> fibers);
    bool tails_only() const { return enc.length_stretch_ > 0 && enc.length_tails_only_ && !wide; }
    struct TailSearch {
        Encoding* e;
        LengthTails::Search search;
    };
    static void tail_starts(std::span<const TailSearch> group);
    void store_codes16();
    void append_decoded(std::vector<Vec3f>& decoded) const;
    void append_exact16(std::vector<Vec3f>& decoded_exact);
    double measure_blocks();
    void append_exact8(std::vector<Vec3f>& decoded_exact, const Vec3f* decoded, double known_max);
};

// Anchors: the block's first two points; a one-point block stores the point
// extrapolated from the previous segment as its second anchor (the tangent
// a renderer needs), a one-point fiber the point itself.
std::pair<Vec3f, Vec3f> FiberEncoder::Encoding::anchor_points(std::uint32_t b) const {
    const std::size_t i0 = std::size_t(b) * points_per_block;
    const Vec3f p0 = fiber[i0];
    if (block_points(b) >= 2) return {p0, fiber[i0 + 1]};
    if (i0 == 0) return {p0, p0};
    return {p0, {2 * p0.x - fiber[i0 - 1].x, 2 * p0.y - fiber[i0 - 1].y, 2 * p0.z - fiber[i0 - 1].z}};
}

void FiberEncoder::Encoding::write_block_heads() {
    if (!wide) return write_block_heads8();
    for (std::uint32_t b = 0; b < n_blocks; ++b) {
        const std::size_t i0 = std::size_t(b) * points_per_block;
        const std::uint32_t n = block_points(b);
        const auto [p0, p1] = anchor_points(b);
        std::uint8_t* block = &out[base + std::size_t(b) * block_bytes];
        const DecoderStarts head = write_block_head16(header, block, p0, p1, fiber_id, b, n_blocks, n);
        scratch.points[i0] = head.a0;
        if (n >= 2) scratch.points[i0 + 1] = head.a1;
        const BlockView16 written{block};
        scratch.frames[b] = frame_from_axis(header.packed() ? packed16_anchor_axis(written) : anchor_axis(head.a0, head.a1));
    }
}

// 8-bit anchors: the nearest roundings' starts four blocks at a time
// (decoder_starts4), then each block's conditioned where its start needs it
// (condition_anchors).
void FiberEncoder::Encoding::write_block_heads8() {
    for (std::uint32_t b0 = 0; b0 < n_blocks; b0 += 4) {
        const std::uint32_t count = std::min<std::uint32_t>(4, n_blocks - b0);
        Vec3d n0[4], n1[4];
        AnchorWords words[4];
        double reach[4];
        DecoderStarts nearest[4];
        for (std::uint32_t i = 0; i < 4; ++i) {
            const std::uint32_t b = b0 + std::min(i, count - 1);  // lanes past the last block repeat it
            const auto [p0, p1] = anchor_points(b);
            n0[i] = normalized_point(header, p0), n1[i] = normalized_point(header, p1);
            words[i] = nearest_words(n0[i], n1[i]);
            reach[i] = block_reach(block_points(b));
        }
        decoder_starts4(words, reach, nearest);
        for (std::uint32_t i = 0; i < count; ++i) {
            const std::uint32_t b = b0 + i, n = block_points(b);
            const DecoderStarts head = condition_anchors(n0[i], n1[i], reach[i], kRobustDivergence, nearest[i]);
            write_block_head8(&out[base + std::size_t(b) * block_bytes], head.words, fiber_id, b, n_blocks, n);
            const std::size_t i0 = std::size_t(b) * points_per_block;
            scratch.points[i0] = head.a0;
            if (n >= 2) scratch.points[i0 + 1] = head.a1;
            scratch.frames[b] = head.frame;
            scratch.starts[b] = head;
        }
    }
}

// The first search of every block with the beam, or (16-bit codes) greedy
// a block at a time: 16-bit codes gain nothing from lanes, their
// nearest-code search is branchy and dominates.
void FiberEncoder::Encoding::search_blocks() {
    const SearchParams params{search().beam_width, search().radius};
    for (std::uint32_t b = 0; b < n_blocks; ++b)
        if (block_points(b) > 2)
            search_block(b, params, wide ? nullptr : codes8_of(b),
                         wide ? scratch.codes16.data() + std::size_t(b) * points_per_block : nullptr,
                         &scratch.points[std::size_t(b) * points_per_block + 2]);
}

void FiberEncoder::Encoding::LaneBlock::take(const BlockBatch& batch, std::size_t j) const {
    std::copy_n(batch.decoded_of(j), m, &e->scratch.points[std::size_t(b) * e->points_per_block + 2]);
    std::copy_n(batch.codes_of(j), m, e->codes8_of(b));
}

// The blocks, longest first (the lanes of a vector then end together),
// with their start states and targets in a batch for the SIMD lanes.
BlockBatch& FiberEncoder::Encoding::batch_of(std::vector<LaneBlock>& blocks) {
    std::stable_sort(blocks.begin(), blocks.end(), [](const LaneBlock& x, const LaneBlock& y) { return x.m > y.m; });
    thread_local BlockBatch batch;
    batch.reset(blocks.front().m, blocks.size());
    for (std::size_t j = 0; j < blocks.size(); ++j) {
        const Encoding& e = *blocks[j].e;
        const std::size_t i0 = std::size_t(blocks[j].b) * e.points_per_block;
        batch.set(j, e.scratch.frames[blocks[j].b], e.scratch.points[i0 + 1],
                  std::span<const Vec3f>(&e.scratch.targets[i0 + 2], blocks[j].m));
    }
    return batch;
}

// The first search of several fibers' blocks: 8-bit greedy or lookahead
// (greedy_blocks.hpp, lookahead_blocks.hpp) has the blocks of all the
// fibers searched together, one per SIMD lane, the longest first (lanes
// of one vector then end together); the same codes as one at a time.
void FiberEncoder::Encoding::search_blocks_together(std::span<Encoding> fibers) {
    if (fibers.empty()) return;
    const Encoding& first = fibers.front();
    if (first.wide || first.search().beam_width > 1 || first.points_per_block <= 2) {
        for (Encoding& e : fibers) e.search_blocks();
        return;
    }
    thread_local std::vector<LaneBlock> blocks;
    blocks.clear();
    for (Encoding& e : fibers)
        for (std::uint32_t b = 0; b < e.n_blocks; ++b)
            if (e.block_points(b) > 2) blocks.push_back({&e, b, e.block_points(b) - 2});
    if (blocks.empty()) return;  // fibers of at most two points a block: no codes
    BlockBatch& batch = batch_of(blocks);
    if (first.search().lookahead > 0)
        lookahead_blocks(first.codebook8(), first.header.step, first.search().lookahead, LookaheadRivals::aim,
                         batch.batch());
    else
        greedy_blocks(first.codebook8(), first.header.step, batch.batch());
    for (std::size_t j = 0; j < blocks.size(); ++j) blocks[j].take(batch, j);
}

// The retry threshold, squared and normalized; 0 where there is no retry.
float FiberEncoder::Encoding::retry_threshold2() const {
    if (!(search().retry_beam_width > 0 && search().retry_error_mm > 0)) return 0;
    const float t = float(search().retry_error_mm / header.scaling);
    return t * t;
}

// Blocks whose largest error exceeds the retry threshold, of all the
// fibers, are searched again; the smaller max error wins. Where the first
// search was the lookahead (8-bit), they are searched first with
// kRetryLookahead points of lookahead in SIMD lanes (retry_with_lookahead:
// on the medium tractogram this takes 96 % of them below the threshold,
// docs/encode.md); those (still) above it get the retry beam.
void FiberEncoder::Encoding::retry_worst_blocks(std::span<Encoding> fibers) {
    if (fibers.empty()) return;
    const Encoding& first = fibers.front();
    const float threshold2 = first.retry_threshold2();
    if (!(threshold2 > 0)) return;
    thread_local std::vector<LaneBlock> blocks;
    blocks.clear();
    for (Encoding& e : fibers)
        for (std::uint32_t b = 0; b < e.n_blocks; ++b) {
            const std::size_t i0 = std::size_t(b) * e.points_per_block;
            const std::uint32_t m = e.block_points(b) > 2 ? e.block_points(b) - 2 : 0;
            if (m == 0) continue;
            const float worst2 = max_distance2(&e.scratch.points[i0 + 2], &e.scratch.targets[i0 + 2], m);
            if (worst2 > threshold2) blocks.push_back({&e, b, m, worst2});
        }
    if (blocks.empty()) return;
    if (!first.wide && first.search().beam_width <= 1 && first.search().lookahead > 0) retry_with_lookahead(blocks);
    for (const LaneBlock& k : blocks)
        if (k.worst2 > threshold2) k.e->retry_with_beam(k.b, k.worst2);
}

// The blocks searched again with the lookahead, all in SIMD lanes; a block
// keeps the new codes (and its worst2 drops) where its largest error drops.
void FiberEncoder::Encoding::retry_with_lookahead(std::vector<LaneBlock>& blocks) {
    const Encoding& first = *blocks.front().e;
    BlockBatch& batch = batch_of(blocks);
    const std::size_t depth = std::max<std::size_t>(first.search().lookahead, kRetryLookahead);
    lookahead_blocks(first.codebook8(), first.header.step, depth, LookaheadRivals::four, batch.batch());
    for (std::size_t j = 0; j < blocks.size(); ++j) {
        LaneBlock& k = blocks[j];
        const Encoding& e = *k.e;
        const std::size_t i0 = std::size_t(k.b) * e.points_per_block;
        const float now = max_distance2(batch.decoded_of(j), &e.scratch.targets[i0 + 2], k.m);
        if (!(now < k.worst2)) continue;
        k.worst2 = now;
        k.take(batch, j);
    }
}

// Block b (largest squared error `first`) searched again with the retry
// beam, the smaller max error kept.
void FiberEncoder::Encoding::retry_with_beam(std::uint32_t b, float first) {
    const SearchParams retry_params{search().retry_beam_width, search().retry_radius};
    // Fixed-step input keeping its lengths walks the sampling step, where
    // a few blocks at sharp turns stay above the retry's reach: those get
    // a wider beam still (length_feedback.hpp, kLengthRescueBeam).
    const bool rescue = enc.length_stretch_ > 0 && enc.length_tails_only_ && !wide;
    const float rescue2 = kLengthRescueOverRetry * kLengthRescueOverRetry * retry_threshold2();
    const std::size_t i0 = std::size_t(b) * points_per_block, m = block_points(b) - 2;
    scratch.retry_points.resize(m);
    scratch.retry_codes8.resize(m);
    scratch.retry_codes16.resize(m);
    for (int pass = 0; pass < 2; ++pass) {
        const unsigned width = pass == 0 ? retry_params.beam : kLengthRescueBeam;
        if (pass == 1 && !(rescue && first > rescue2 && width > retry_params.beam)) break;
        search_block(b, SearchParams{width, retry_params.radius}, scratch.retry_codes8.data(),
                     scratch.retry_codes16.data(), scratch.retry_points.data());
        const float now = max_distance2(scratch.retry_points.data(), &scratch.targets[i0 + 2], m);
        if (!(now < first)) continue;
        first = now;
        std::copy(scratch.retry_points.begin(), scratch.retry_points.end(), &scratch.points[i0 + 2]);
        if (wide)
            std::copy(scratch.retry_codes16.begin(), scratch.retry_codes16.end(),
                      scratch.codes16.begin() + std::ptrdiff_t(i0));
        else
            std::copy(scratch.retry_codes8.begin(), scratch.retry_codes8.end(), codes8_of(b));
    }
}

// Robust blocks (8-bit): where the exact decoder's first frame departs
// from the float one, search again for codes that suit both (aiming at
// the middle of the two decoders' targets), and keep whichever codes
// have the smaller worst error over both decoders.
void FiberEncoder::Encoding::search_robust_blocks() {
    const Codebook8 cb = codebook8();
    const unsigned robust_beam = std::max({8u, search().beam_width, search().retry_beam_width});
    for (std::uint32_t b = 0; b < n_blocks; ++b) {
        const std::size_t i0 = std::size_t(b) * points_per_block, m = block_points(b) > 2 ? block_points(b) - 2 : 0;
        if (m == 0 || !robust(b)) continue;
        const std::span<const Vec3f> t(&scratch.targets[i0 + 2], m);
        scratch.alt.resize(m);
        exact_decoder_targets(scratch.starts[b], t, scratch.alt.data());
        float best = worst_error2(&scratch.points[i0 + 2], t.data(), scratch.alt.data(), m);
        // What the float decoder alone gets: once the robust codes come
        // within 10 % of it for both decoders, the wide beam is not worth its cost.
        const float float_only = max_distance2(&scratch.points[i0 + 2], t.data(), m);
        scratch.retry_points.resize(m);
        scratch.retry_codes8.resize(m);
        for (unsigned width : {1u, robust_beam}) {
            if (width > 1 && best <= 1.21f * float_only) break;
            if (width == 1 && search().lookahead > 0)  // as the first search: greedy aiming with lookahead
                LookaheadSearch<Codebook8>(cb, header.step, search().lookahead, LookaheadRivals::aim)
                    .run(scratch.frames[b], scratch.points[i0 + 1], t, scratch.retry_codes8.data(),
                         scratch.retry_points.data(), std::span<const Vec3f>(scratch.alt));
            else
                search_codes(cb, SearchParams{width, 1}, scratch.frames[b], scratch.points[i0 + 1], header.step, t,
                             scratch.retry_codes8.data(), scratch.retry_points.data(),
                             std::span<const Vec3f>(scratch.alt));
            const float worst = worst_error2(scratch.retry_points.data(), t.data(), scratch.alt.data(), m);
            if (!(worst < best)) continue;
            best = worst;
            std::copy(scratch.retry_points.begin(), scratch.retry_points.end(), &scratch.points[i0 + 2]);
            std::copy(scratch.retry_codes8.begin(), scratch.retry_codes8.end(), codes8_of(b));
        }
    }
}

// Length feedback across the blocks (length_feedback.hpp), with the
// block's own search (fixed-step tails) or the retry's beam; robust blocks
// keep the codes that suit both decoders.
void FiberEncoder::Encoding::keep_lengths() {
    const float stretch = enc.length_stretch_;
    if (!(stretch > 0)) return;
    const SearchParams feedback_params{std::max({8u, search().beam_width, search().retry_beam_width}), 1};
    scratch.retry_codes8.resize(points_per_block);
    scratch.retry_codes16.resize(points_per_block);
    feed_back_length(
        targets(), points(), points_per_block, stretch,
        [&](std::uint32_t blk) { return wide || !robust(blk); },
        [&](std::uint32_t blk, std::span<const Vec3f> t, Vec3f* dec) {
            const std::size_t i0 = std::size_t(blk) * points_per_block;
            if (wide)
                search_codes(Codebook16{*enc.tables_->table16}, feedback_params, scratch.frames[blk],
                             scratch.points[i0 + 1], header.step, t, scratch.retry_codes16.data(), dec);
            else
                search_codes(codebook8(), feedback_params, scratch.frames[blk], scratch.points[i0 + 1], header.step, t,
                             scratch.retry_codes8.data(), dec);
        },
        [&](std::uint32_t blk) {
            const std::size_t i0 = std::size_t(blk) * points_per_block, m = block_points(blk) - 2;
            if (wide)
                std::copy_n(scratch.retry_codes16.begin(), m, scratch.codes16.begin() + std::ptrdiff_t(i0));
            else
                std::copy_n(scratch.retry_codes8.begin(), m, codes8_of(blk));
        });
}

// The decoder's states before code j0 of the group's tail searches'
// blocks (group[i].search), replayed from each block's start (once for a
// block's tries: the fiber's cache), the blocks' frame products in step
// with each other (each is a chain of dependent products).
void FiberEncoder::Encoding::tail_starts(std::span<const TailSearch> group) {
    struct Replay {
        Scratch::TailStart* c;
        const std::uint8_t* codes;
    };
    thread_local std::vector<Replay> replays;
    replays.clear();
    std::size_t longest = 0;
    for (const TailSearch& g : group) {
        Scratch::TailStart& c = g.e->scratch.tail_start;
        const LengthTails::Search& t = g.search;
        if (c.block == t.block && c.j0 == t.j0) continue;
        c = {t.block, t.j0, g.e->scratch.frames[t.block],
             g.e->scratch.points[std::size_t(t.block) * g.e->points_per_block + 1 + t.j0]};
        replays.push_back({&c, g.e->codes8_of(t.block)});
        longest = std::max(longest, t.j0);
    }
    if (replays.empty()) return;
    const Codebook8 cb = group.front().e->codebook8();
    for (std::size_t k = 0; k < longest; ++k)
        for (const Replay& r : replays)
            if (k < r.c->j0) r.c->f = compose(r.c->f, cb.frame(r.codes[k]));
}

// The fixed-step length tails (length_feedback.hpp) of several fibers,
// with the block's own search. Each fiber's tails depend on its earlier
// blocks' outcome, so a fiber has one search at a time, but the fibers'
// searches are independent: lookahead searches of the same length run
// together, one per SIMD lane (lookahead_blocks.hpp).
void FiberEncoder::Encoding::keep_length_tails(std::span<Encoding> fibers) {
    std::vector<TailSearch> waiting, group;
    auto next = [&](Encoding& e) {
        TailSearch p{&e, {}};
        if (e.scratch.tails->next([&](std::uint32_t b) { return !e.robust(b); }, p.search)) waiting.push_back(p);
    };
    for (Encoding& e : fibers) {
        e.scratch.tail_start = {};
        e.scratch.tails.emplace(e.targets(), e.points(), e.points_per_block, kLengthFeedbackTail, kLengthFeedbackActShare,
                                kLengthFeedbackFarActShare, kLengthFeedbackNearBlocks);
        next(e);
    }
    if (fibers.empty()) return;
    const Encoding& first = fibers.front();
    const Codebook8 cb = first.codebook8();
    const SearchOptions& search = first.search();
    const bool lookahead = search.beam_width <= 1 && search.lookahead > 0;
    const std::size_t depth = std::max(search.lookahead, kLengthFeedbackLookahead);
    thread_local BlockBatch batch;
    while (!waiting.empty()) {
        // Every waiting search of the first one's length (lookahead), or the first.
        group.clear();
        const std::size_t m = waiting.front().search.targets.size();
        std::size_t kept = 0;
        for (const TailSearch& p : waiting) {
            if ((lookahead || group.empty()) && p.search.targets.size() == m) group.push_back(p);
            else waiting[kept++] = p;
        }
        waiting.resize(kept);
        batch.reset(m, group.size());
        tail_starts(group);
        for (std::size_t i = 0; i < group.size(); ++i) {
            const Scratch::TailStart& start = group[i].e->scratch.tail_start;
            batch.set(i, start.f, start.p, group[i].search.targets);
        }
        if (lookahead)
            lookahead_blocks(cb, first.header.step, depth, LookaheadRivals::aim, batch.batch());
        else
            search_codes(cb, SearchParams{search.beam_width, search.radius}, batch.frames[0], batch.points[0],
                         first.header.step, group[0].search.targets, batch.codes.data(), batch.decoded.data() + 1);
        for (std::size_t i = 0; i < group.size(); ++i) {
            Encoding& e = *group[i].e;
            std::copy_n(batch.decoded_of(i), m, e.scratch.tails->candidate());
            if (e.scratch.tails->judge())
                std::copy_n(batch.codes_of(i), m, e.codes8_of(group[i].search.block) + group[i].search.j0);
            next(e);
        }
    }
}

void FiberEncoder::Encoding::store_codes16() {
    for (std::uint32_t b = 0; b < n_blocks; ++b)
        for (std::size_t k = 0; k + 2 < block_points(b); ++k)
            put_le(&out[base + std::size_t(b) * block_bytes + kBlock16DirectionsOffset + 2 * k],
                   scratch.codes16[std::size_t(b) * points_per_block + k], 2);
}

void FiberEncoder::Encoding::append_decoded(std::vector<Vec3f>& decoded) const {
    // FftHeader::to_world per coordinate, so that the compiler vectorizes it.
    const std::size_t at = decoded.size();
    decoded.resize(at + n_points);
    if (n_points == 0) return;
    // The header's fields in locals and restrict pointers: the stores could
    // otherwise alias them, which kept this loop scalar, reloading them.
    const float* __restrict in = &scratch.points[0].x;
    float* __restrict world = &decoded[at].x;
    const float scaling = header.scaling, offset[3] = {header.offset[0], header.offset[1], header.offset[2]};
    for (std::size_t k = 0; k < n_points; ++k)
        for (int c = 0; c < 3; ++c) world[3 * k + c] = (in[3 * k + c] - 0.5f) * scaling - offset[c];
}

// The exact decode of every 16-bit block: no bound on the walks' divergence
// is tight enough at 254 points to skip blocks (walk_divergence gives ~3 um
// where they differ by ~0.1 um).
void FiberEncoder::Encoding::append_exact16(std::vector<Vec3f>& decoded_exact) {
    scratch.walked.resize(points_per_block);
    decoded_exact.reserve(decoded_exact.size() + n_points);
    for (std::uint32_t b = 0; b < n_blocks; ++b) {
        const BlockView16 blk{&out[base + std::size_t(b) * block_bytes]};
        const std::array<std::uint32_t, 3> q0{blk.anchor_word(0), blk.anchor_word(1), blk.anchor_word(2)};
        const std::array<std::uint32_t, 3> q1{blk.anchor_word(3), blk.anchor_word(4), blk.anchor_word(5)};
        auto anchor = [](const std::array<std::uint32_t, 3>& q) {
            return Vec3d{double(q[0]) / kUnorm24Max, double(q[1]) / kUnorm24Max, double(q[2]) / kUnorm24Max};
        };
        const std::size_t i0 = std::size_t(b) * points_per_block, n = block_points(b), m = n > 2 ? n - 2 : 0;
        decoded_exact.push_back(world(anchor(q0)));
        if (n < 2) continue;
        decoded_exact.push_back(world(anchor(q1)));
        exact_walk(*enc.tables_->exact16, exact_block_frame24(q0, q1), anchor(q1), double(header.step),
                   scratch.codes16.data() + i0, m, scratch.walked.data());
        for (std::size_t k = 0; k < m; ++k) decoded_exact.push_back(world(scratch.walked[k]));
    }
}

// Each 8-bit block's largest float error (normalized units); returns the
// fiber's largest.
double FiberEncoder::Encoding::measure_blocks() {
    scratch.block_errors.resize(n_blocks);
    double fiber_max = 0;
    for (std::uint32_t b = 0; b < n_blocks; ++b) {
        const std::size_t i0 = std::size_t(b) * points_per_block;
        scratch.block_errors[b] =
            std::sqrt(double(max_distance2(&scratch.points[i0], &scratch.targets[i0], block_points(b))));
        fiber_max = std::max(fiber_max, scratch.block_errors[b]);
    }
    return fiber_max;
}

// The exact decode of 8-bit blocks (after measure_blocks). A block whose
// first frame is well conditioned (not robust()) and whose float errors
// plus the bound on the two decoders' divergence stay below `known_max`, a
// float error of a point measured with it (the largest of the fibers
// encoded together), cannot raise the max error, and its exact points
// differ from the float ones by rounding only: it gets the float points
// (nearly every block), which keeps the cost of this pass small.
void FiberEncoder::Encoding::append_exact8(std::vector<Vec3f>& decoded_exact, const Vec3f* decoded, double known_max) {
    scratch.walked.resize(points_per_block);
    const double out_slack =
        4 * 0x1p-24 *
        (1 + std::max({std::fabs(header.offset[0]), std::fabs(header.offset[1]), std::fabs(header.offset[2])}) /
                 header.scaling);
    decoded_exact.reserve(decoded_exact.size() + n_points);
    for (std::uint32_t b = 0; b < n_blocks; ++b) {
        const DecoderStarts& e = scratch.starts[b];
        const std::size_t i0 = std::size_t(b) * points_per_block, n = block_points(b), m = n > 2 ? n - 2 : 0;
        const double bound = e.divergence + walk_divergence(m, double(header.step)) + out_slack;
        if (!robust(b) && scratch.block_errors[b] + bound <= known_max) {
            // Not the worst even if the exact decode is off by the bound:
            // the float decode's points stand for it.
            if (decoded) {
                append_points(decoded_exact, decoded + i0, n);
            } else {
                for (std::size_t k = 0; k < n; ++k)
                    decoded_exact.push_back(
                        header.to_world(scratch.points[i0 + k].x, scratch.points[i0 + k].y, scratch.points[i0 + k].z));
            }
            continue;
        }
        exact_walk(*enc.tables_->exact8, e.exact_frame, e.exact1, double(header.step), codes8_of(b), m,
                   scratch.walked.data());
        decoded_exact.push_back(world(e.exact0));
        if (n >= 2) decoded_exact.push_back(world(e.exact1));
        for (std::size_t k = 0; k < m; ++k) decoded_exact.push_back(world(scratch.walked[k]));
    }
}

// The passes over each fiber, in order (each one's comment says what it
// does); the first search and the length tails of all the fibers together,
// their blocks in SIMD lanes.
void FiberEncoder::encode_fibers(std::span<const std::span<const Vec3f>> fibers, std::uint32_t first_id,
                                 std::vector<std::uint8_t>& out, std::vector<Vec3f>* decoded,
                                 std::vector<Vec3f>* decoded_exact) const {
    for (std::size_t i = 0; i < fibers.size(); ++i)
        if (block_count(fibers[i].size()) > 0xffff)
            throw Error(Errc::unsupported, "fiber " + std::to_string(first_id + i) + " has " +
                                               std::to_string(fibers[i].size()) + " points: more than 65535 blocks");
    thread_local std::vector<Encoding::Scratch> scratch;
    if (scratch.size() < fibers.size()) scratch.resize(fibers.size());
    std::vector<Encoding> es;
    es.reserve(fibers.size());
    for (std::size_t i = 0; i < fibers.size(); ++i) es.emplace_back(*this, fibers[i], std::uint32_t(first_id + i), out, scratch[i]);
    for (Encoding& e : es) e.write_block_heads();
    Encoding::search_blocks_together(es);
    Encoding::retry_worst_blocks(es);
    for (Encoding& e : es)
        if (!e.wide) e.search_robust_blocks();
    if (!es.empty() && es.front().tails_only()) Encoding::keep_length_tails(es);
    else for (Encoding& e : es) e.keep_lengths();
    // The largest float error of these fibers' points: the max error
    // measured over their decoded points is at least that.
    double group_max = 0;
    if (decoded_exact)
        for (Encoding& e : es)
            if (!e.wide) group_max = std::max(group_max, e.measure_blocks());
    for (Encoding& e : es) {
        if (e.wide) e.store_codes16();
        if (decoded) e.append_decoded(*decoded);
        const Vec3f* fiber_decoded = decoded ? decoded->data() + (decoded->size() - e.n_points) : nullptr;
        if (decoded_exact) e.wide ? e.append_exact16(*decoded_exact) : e.append_exact8(*decoded_exact, fiber_decoded, group_max);
    }
}

void FiberEncoder::encode(std::span<const Vec3f> fiber, std::uint32_t fiber_id, std::vector<std::uint8_t>& out,
                          std::vector<Vec3f>* decoded, std::vector<Vec3f>* decoded_exact) const {
    encode_fibers(std::span<const std::span<const Vec3f>>(&fiber, 1), fiber_id, out, decoded, decoded_exact);
}

}  // namespace fiblet
