// The query executor. Three passes, each touching only what it must:
//   1. fiber criteria (IDs, length, random subset): no I/O, the index knows
//      every fiber's point count;
//   2. fibers-mode regions: the blocks near a region (from the index) are
//      decoded and their points tested, which decides whole fibers (with
//      ends_only, each fiber's first and last blocks); then inverse, skip
//      and number act on the fibers kept;
//   3. the blocks of the kept fibers that the view / blocks-mode regions may
//      keep (from the index) are read, tested on their header (sphere, level
//      of detail) or points, decoded and handed out as runs.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>

#include "fiblet/error.hpp"
#include "fiblet/fiber_regions.hpp"
#include "fiblet/select.hpp"
#include "core/default_init_allocator.hpp"
#include "select/block_bits.hpp"
#include "select/block_batch_reader.hpp"
#include "select/block_bounds.hpp"
#include "select/block_decoder.hpp"
#include "select/points_in_region.hpp"
#include "index/block_spheres.hpp"
#include "select/query_checks.hpp"

namespace fiblet {

namespace {

using Bits = std::vector<std::uint64_t>;

// Blocks handled at a time: about 2^18 points (blocks hold 2 to 16383).
std::size_t batch_blocks(const FftHeader& h) {
    return std::clamp<std::size_t>((std::size_t{1} << 18) / h.points_per_block, 16, 4096);
}

// Blocks decoded into the output with one call: about a chunk's points, so
// that the output buffer stays the size of a few chunks, in cache and clear
// of page faults (docs/select.md, "Chunks").
std::size_t piece_blocks(const FftHeader& h, const SelectOptions& o) {
    return std::clamp<std::size_t>(o.chunk_points / h.points_per_block, 1, batch_blocks(h));
}

using detail::has_bit;
using detail::any_point_in;

void and_bits(Bits& a, const Bits& b) {
    for (std::size_t i = 0; i < a.size(); ++i) a[i] &= b[i];
}

// The fiber of each block, for blocks visited in ascending order. The
// current fiber's end is kept: most blocks asked for lie in the fiber of the
// one before, and the file's table would be read again after every store
// the caller makes (the compiler cannot tell they do not change it).
class FiberCursor {
public:
    explicit FiberCursor(const FftFile& file) : file_(file), end_(file.block_end(1)) {}
    std::uint64_t fiber_of(std::uint64_t block) {
        while (end_ <= block) end_ = file_.block_end(++fiber_ + 1);
        return fiber_;
    }

private:
    const FftFile& file_;
    std::uint64_t fiber_ = 0;
    std::uint64_t end_;  // of fiber_'s blocks
};

// The blocks of kept fibers in ascending order, restricted to a bitmap of
// candidate blocks when there is one, a batch at a time.
class CandidateBlocks {
public:
    CandidateBlocks(const FftFile& file, const std::vector<std::uint8_t>& keep, const Bits* only)
        : file_(file), keep_(keep), only_(only), cursor_(file) {}

    // Fills `blocks` / `fibers` with up to `max` candidates; false when none is left.
    bool next(std::size_t max, std::vector<std::uint32_t>& blocks, std::vector<std::uint64_t>& fibers) {
        blocks.clear(), fibers.clear();
        const std::uint64_t nblocks = file_.header().blocks;
        if (only_) {
            // The bitmap's position in locals: the outputs' stores might
            // otherwise be this object's and make the compiler reload it.
            std::size_t word = word_;
            std::uint64_t bits = word_bits_;
            const std::uint64_t* const words = only_->data();
            const std::size_t word_count = only_->size();
            const std::uint8_t* const keep = keep_.data();
            while (blocks.size() < max) {
                if (bits == 0) {
                    if (++word >= word_count) break;
                    bits = words[word];
                    continue;
                }
                const std::uint64_t b = word * 64 + std::uint64_t(std::countr_zero(bits));
                bits &= bits - 1;
                if (b >= nblocks) break;
                const std::uint64_t f = cursor_.fiber_of(b);
                if (keep[f]) blocks.push_back(std::uint32_t(b)), fibers.push_back(f);
            }
            word_ = word, word_bits_ = bits;
        } else {
            const std::uint64_t nfibers = file_.header().fibers;
            while (blocks.size() < max && fiber_ < nfibers) {
                if (!keep_[fiber_]) {
                    ++fiber_, in_fiber_ = 0;
                    continue;
                }
                const std::uint64_t first = file_.first_block(fiber_), count = file_.block_count(fiber_);
                while (in_fiber_ < count && blocks.size() < max)
                    blocks.push_back(std::uint32_t(first + in_fiber_++)), fibers.push_back(fiber_);
                if (in_fiber_ == count) ++fiber_, in_fiber_ = 0;
            }
        }
        return !blocks.empty();
    }

private:
    const FftFile& file_;
    const std::vector<std::uint8_t>& keep_;
    const Bits* only_;
    FiberCursor cursor_;
    std::size_t word_ = std::size_t(-1);
    std::uint64_t word_bits_ = 0;
    std::uint64_t fiber_ = 0, in_fiber_ = 0;
};

// Decodes `count` consecutive blocks (contiguous in memory) into xyz, which
// must have room; returns their point counts' sum. Validates the counts.
std::size_t decode_into(const DecodeContext& ctx, const std::uint8_t* blocks, std::size_t count,
                        detail::UninitializedVector<float>& xyz, std::size_t at_point) {
    const std::size_t n = count_block_points(ctx, blocks, count);
    if (xyz.size() < 3 * (at_point + n)) xyz.resize(3 * (at_point + n));
    detail::decode_selected_blocks(ctx, blocks, count, &xyz[3 * at_point]);
    return n;
}

Vec3f first_point(const FftHeader& h, const std::uint8_t* block);

Vec3f first_point(const FftHeader& h, const std::uint8_t* block) {
    const auto a = block_anchors_normalized(h, block);
    return h.to_world(a[0], a[1], a[2]);
}

// Assembles kept blocks into runs and hands chunks of them to the sink.
// Fine blocks are decoded straight into the output buffer at its frontier
// and stay where they are: a rejected block leaves unused points between
// two runs instead of making the next ones move. The buffer only grows.
class RunWriter {
public:
    RunWriter(const SelectOptions& o, const std::function<void(const SelectedChunk&)>& sink, SelectionStats& stats,
              std::size_t piece_points)
        : options_(o), sink_(sink), stats_(stats) {
        // Room for a full chunk and a piece decoded after it: no reallocation
        // (a copy and fresh pages each time).
        if (o.points) xyz_.reserve(3 * (o.chunk_points + 2 * piece_points));
    }

    // Closes the open run unless `block` of `fiber` continues it.
    void break_unless_continues(std::uint64_t fiber, std::uint64_t block) {
        if (open_ && (run_.fiber != fiber || run_.first_block + run_.block_count != block)) close();
    }
    // The output buffer and its frontier (in points), where blocks are
    // decoded; advance() moves the frontier past them.
    detail::UninitializedVector<float>& buffer() { return xyz_; }
    std::size_t frontier() const { return frontier_; }
    void advance(std::size_t points) { frontier_ += points; }

    // A fine block of n points, decoded at point index `at` (ignored when
    // points are not output). A block that continues the open run lies
    // right after it, since both were decoded in order.
    void fine(std::uint64_t fiber, std::uint64_t block, std::size_t at, std::uint32_t n) {
        extend(fiber, block, at);
        run_end_ += n;
        stats_.points += n;
        has_end_ = false;
    }
    // A coarse block: its first point now (at the frontier), `end` when the
    // run stops after it.
    void coarse(std::uint64_t fiber, std::uint64_t block, Vec3f first, const Vec3f* end) {
        break_unless_continues(fiber, block);  // first: closing may put an end point at the frontier
        extend(fiber, block, frontier_);
        ++run_.coarse_blocks, ++stats_.coarse_blocks;
        put(run_end_++, first);
        frontier_ = std::max(frontier_, run_end_);
        has_end_ = end != nullptr;
        if (end) end_point_ = *end;
    }
    // Hands the closed runs to the sink when the chunk is full (the open
    // run's points move to the front); only where no decoded points wait
    // after the frontier.
    void maybe_flush() {
        if (runs_.empty() || (frontier_ < options_.chunk_points && runs_.size() < options_.chunk_points)) return;
        flush();
        if (open_) {
            if (options_.points && run_first_ > 0)
                std::memmove(xyz_.data(), &xyz_[3 * run_first_], 12 * (run_end_ - run_first_));
            run_end_ -= run_first_, run_first_ = 0;
        }
        frontier_ = open_ ? run_end_ : 0;
    }
    void finish() {
        close();
        if (!runs_.empty()) flush();
    }

private:
    void extend(std::uint64_t fiber, std::uint64_t block, std::size_t at) {
        break_unless_continues(fiber, block);
        if (!open_) {
            if (fiber != last_fiber_) ++stats_.fibers, last_fiber_ = fiber;
            run_ = {fiber, block, 0, 0};
            run_first_ = run_end_ = at;
            open_ = true;
        }
        ++run_.block_count, ++stats_.blocks;
    }
    void put(std::size_t at, Vec3f p) {
        ++stats_.points;
        if (!options_.points) return;
        if (xyz_.size() < 3 * (at + 1)) xyz_.resize(std::max(3 * (at + 1), 2 * xyz_.size()));
        xyz_[3 * at] = p.x, xyz_[3 * at + 1] = p.y, xyz_[3 * at + 2] = p.z;
    }
    void close() {
        if (!open_) return;
        // The end point of a last coarse block goes right after the run: at
        // the frontier, or over the points of the rejected block that broke
        // the run (it has at least one).
        if (has_end_) {
            put(run_end_++, end_point_);
            frontier_ = std::max(frontier_, run_end_);
            has_end_ = false;
        }
        open_ = false;
        ++stats_.runs;
        runs_.push_back(run_);
        if (options_.points) first_.push_back(run_first_), count_.push_back(run_end_ - run_first_);
        chunk_points_ += run_end_ - run_first_;
    }
    void flush() {
        SelectedChunk c;
        c.runs = runs_;
        if (options_.points) c.xyz = {xyz_.data(), 3 * frontier_}, c.first = first_, c.count = count_;
        c.points = options_.points ? chunk_points_ : 0;
        sink_(c);
        first_.clear(), count_.clear(), runs_.clear();
        chunk_points_ = 0;
    }

    const SelectOptions& options_;
    const std::function<void(const SelectedChunk&)>& sink_;
    SelectionStats& stats_;
    detail::UninitializedVector<float> xyz_;  // size only grows; written where it grows
    std::size_t frontier_ = 0;                // points of the buffer in use
    std::size_t run_first_ = 0, run_end_ = 0;  // the open run's points
    std::vector<std::uint64_t> first_, count_;
    std::uint64_t chunk_points_ = 0;
    std::vector<SelectedRun> runs_;
    SelectedRun run_;
    bool open_ = false, has_end_ = false;
    Vec3f end_point_{};
    std::uint64_t last_fiber_ = ~std::uint64_t{0};
};

class Selector {
public:
    Selector(const FftFile& file, const BlockIndex& index, const Query& q, const SelectOptions& o)
        : file_(file), index_(index), q_(q), options_(o), h_(file.header()), ctx_(file), reader_(file, o.map_file),
          // A stored index describes the blocks as written: trusted to say a
          // block lies wholly inside a region only when the checksums tie it
          // to the blocks read (a damaged block read unverified may be elsewhere).
          trust_inside_(index.source() == BlockIndex::Source::decoded || file.verifies_checksums()),
          // Stored boxes (of groups of blocks, or of blocks on a grid of half a
          // block's path) are narrowed down from each block's header.
          coarse_index_(index.max_join() >= 0) {
        if (index.blocks() != h_.blocks || index.fibers() != h_.fibers)
            throw Error(Errc::invalid_argument, file.path() + ": the block index belongs to another file");
        detail::check_query(q);
    }

    SelectionStats run(const std::function<void(const SelectedChunk&)>& sink) {
        fiber_criteria();
        if (q_.roi_mode == RoiMode::fibers && !(q_.include.empty() && q_.exclude.empty()))
            q_.ends_only ? fiber_region_ends() : fiber_regions();
        if (q_.inverse)
            for (auto& k : keep_) k = !k;
        skip_and_number();
        blocks(sink);
        stats_.blocks_read = reader_.blocks_read();
        return stats_;
    }

private:
    // Blocks whose box meets a region (and, in `inside`, those wholly in it).
    Bits near(const Region& r, Bits* inside = nullptr) const {
        Bits bits = blocks_near(index_, r, trust_inside_ ? inside : nullptr);  // untrusted: their points are tested
        if (inside) inside->resize(bits.size(), 0);
        return bits;
    }
    Bits near_any(const std::vector<Region>& regions, Bits* inside = nullptr) const {
        Bits all((h_.blocks + 63) / 64, 0);
        if (inside) inside->assign(all.size(), 0);
        for (const Region& r : regions) {
            Bits in;
            const Bits b = near(r, inside ? &in : nullptr);
            for (std::size_t i = 0; i < all.size(); ++i) all[i] |= b[i];
            if (inside)
                for (std::size_t i = 0; i < all.size(); ++i) (*inside)[i] |= in[i];
        }
        return all;
    }

    // Pass 1: IDs, length, random subset.
    void fiber_criteria() {
        const std::uint64_t n = h_.fibers;
        keep_.assign(n, q_.fibers.empty() ? 1 : 0);
        for (const FiberRange& r : q_.fibers)
            for (std::uint64_t f = r.first; f <= std::min(r.last, n ? n - 1 : 0) && f < n; ++f) keep_[f] = 1;
        if (!q_.min_length_mm && !q_.max_length_mm && !q_.random_fraction) return;
        for (std::uint64_t f = 0; f < n; ++f) {
            if (!keep_[f]) continue;
            const double len = fiber_length_mm(h_, index_.fiber_points(f));
            if ((q_.min_length_mm && len < *q_.min_length_mm) || (q_.max_length_mm && len > *q_.max_length_mm) ||
                (q_.random_fraction && !in_random_subset(f, *q_.random_fraction, q_.random_seed)))
                keep_[f] = 0;
        }
    }

    // Pass 2 (fibers mode): what the regions test, fiber by fiber.
    struct RegionTests {
        std::vector<Bits> near_include, inside_include;  // per include region: blocks near it, wholly inside it
        Bits near_exclude;                               // blocks near an exclude region
        std::uint64_t all_includes = 0;                  // the bits of every include region
        std::vector<std::uint64_t> met;                  // per fiber: the include regions its points meet
        std::vector<std::uint8_t> excluded;              // per fiber: a point in an exclude region
        bool tests(std::size_t k, std::uint64_t f, std::uint64_t b) const {  // include k, to be tested on block b?
            return !(met[f] >> k & 1) && has_bit(near_include[k], b);
        }
    };

    // Pass 2 (fibers mode): a fiber must meet every include region and no
    // exclude region. Only blocks the index puts near a region are decoded.
    void fiber_regions() {
        RegionTests t = region_tests();
        test_decoded_blocks(t, blocks_to_decode(t));
        for (std::uint64_t f = 0; f < h_.fibers; ++f)
            if (t.met[f] != t.all_includes || t.excluded[f]) keep_[f] = 0;
    }

    // The regions' blocks from the index. Fibers with no block near some
    // include region fail without decoding; a block wholly inside a region
    // meets it without decoding.
    RegionTests region_tests() {
        const std::size_t k_inc = q_.include.size();
        RegionTests t{.near_include = std::vector<Bits>(k_inc),
                      .inside_include = std::vector<Bits>(k_inc),
                      .near_exclude = near_any(q_.exclude),
                      .all_includes = k_inc == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << k_inc) - 1,
                      .met = std::vector<std::uint64_t>(h_.fibers, 0),
                      .excluded = std::vector<std::uint8_t>(h_.fibers, 0)};
        std::vector<std::uint64_t> may_meet(h_.fibers, 0);
        for (std::size_t k = 0; k < k_inc; ++k) {
            t.near_include[k] = near(q_.include[k], &t.inside_include[k]);
            FiberCursor cursor(file_);
            for (std::size_t w = 0; w < t.near_include[k].size(); ++w)
                for (std::uint64_t bits = t.near_include[k][w]; bits; bits &= bits - 1) {
                    const std::uint64_t b = w * 64 + std::uint64_t(std::countr_zero(bits));
                    const std::uint64_t f = cursor.fiber_of(b);
                    may_meet[f] |= std::uint64_t{1} << k;
                    if (has_bit(t.inside_include[k], b)) t.met[f] |= std::uint64_t{1} << k;
                }
        }
        for (std::uint64_t f = 0; f < h_.fibers; ++f)
            if (may_meet[f] != t.all_includes) keep_[f] = 0;
        return t;
    }

    // Blocks near an exclude region, and blocks near (not wholly inside) an
    // include region that their fiber has not met yet.
    Bits blocks_to_decode(const RegionTests& t) const {
        Bits to_test = t.near_exclude;
        for (std::size_t k = 0; k < t.near_include.size(); ++k) {
            FiberCursor cursor(file_);
            for (std::size_t w = 0; w < t.near_include[k].size(); ++w)
                for (std::uint64_t bits = t.near_include[k][w] & ~t.inside_include[k][w]; bits; bits &= bits - 1) {
                    const std::uint64_t b = w * 64 + std::uint64_t(std::countr_zero(bits));
                    if (!(t.met[cursor.fiber_of(b)] >> k & 1)) to_test[w] |= std::uint64_t{1} << (b & 63);
                }
        }
        return to_test;
    }

    // Whether block i of a read batch is decoded: its bound from headers
    // (block_bound) meets a region it is tested against; the index's boxes
    // are coarser (quantized, or of groups of blocks).
    bool bound_meets_a_region(const RegionTests& t, std::size_t i, std::uint64_t f, std::uint64_t b) const {
        if (!coarse_index_) return true;  // exact boxes (computed) or no join bound (version 1)
        if (!q_.exclude.empty() && has_bit(t.near_exclude, b) && bound_meets_any(q_.exclude, exclude_meets_, i))
            return true;
        for (std::size_t k = 0; k < q_.include.size(); ++k)
            if (t.tests(k, f, b) && bound_meets(q_.include[k], include_meets_[k], i)) return true;
        return false;
    }

    // The candidate blocks decoded, a batch at a time, and their points
    // tested against the regions.
    void test_decoded_blocks(RegionTests& t, const Bits& to_test) {
        CandidateBlocks candidates(file_, keep_, &to_test);
        std::vector<std::uint32_t> blocks;
        std::vector<std::uint64_t> fibers;
        const std::uint32_t bb = h_.block_bytes();
        std::vector<std::size_t> tested, first_point;
        while (candidates.next(batch_blocks(h_), blocks, fibers)) {
            stats_.blocks_tested += blocks.size();
            read_with_next(blocks, fibers, coarse_index_);  // the next block's first point narrows a bound
            if (coarse_index_) spheres_of_read(need_.size()), bounds_of_read(blocks.size(), true);
            tested.clear();
            for (std::size_t i = 0; i < blocks.size(); ++i)
                if (!t.excluded[fibers[i]] && bound_meets_a_region(t, i, fibers[i], blocks[i])) tested.push_back(i);
            if (tested.empty()) continue;
            // One decode call for the whole batch (SIMD decoders fill their lanes).
            const std::uint8_t* bytes =
                contiguous(tested, [&](std::size_t i) { return reader_.block(at_need_[i]); });
            decode_into(ctx_, bytes, tested.size(), scratch_, 0);
            first_point.assign(tested.size() + 1, 0);
            for (std::size_t j = 0; j < tested.size(); ++j)
                first_point[j + 1] = first_point[j] + block_flags(h_, bytes + j * bb).point_count;
            stats_.blocks_decoded += tested.size();
            for (std::size_t j = 0; j < tested.size(); ++j) {
                const std::size_t i = tested[j];
                const std::uint64_t f = fibers[i], b = blocks[i];
                if (t.excluded[f]) continue;
                const float* p = &scratch_[3 * first_point[j]];
                const auto n = std::uint32_t(first_point[j + 1] - first_point[j]);
                for (std::size_t k = 0; k < q_.include.size(); ++k)
                    if (t.tests(k, f, b) && any_point_in(q_.include[k], p, n)) t.met[f] |= std::uint64_t{1} << k;
                if (!q_.exclude.empty() && has_bit(t.near_exclude, b) && any_point_in(q_.exclude, p, n)) t.excluded[f] = 1;
            }
        }
    }

    // Pass 2 with ends_only: a fiber's first and last points must meet
    // every include region and no exclude region. Decoded: the first and
    // last block of each kept fiber.
    void fiber_region_ends() {
        Bits ends((h_.blocks + 63) / 64, 0);
        for (std::uint64_t f = 0; f < h_.fibers; ++f) {
            if (!keep_[f] || file_.block_count(f) == 0) continue;
            for (const std::uint64_t b : {file_.first_block(f), file_.first_block(f) + file_.block_count(f) - 1})
                ends[b >> 6] |= std::uint64_t{1} << (b & 63);
        }
        std::vector<std::array<Vec3f, 2>> end_points(h_.fibers);
        CandidateBlocks candidates(file_, keep_, &ends);
        std::vector<std::uint32_t> blocks;
        std::vector<std::uint64_t> fibers;
        std::vector<std::size_t> all;
        const std::uint32_t bb = h_.block_bytes();
        while (candidates.next(batch_blocks(h_), blocks, fibers)) {
            stats_.blocks_tested += blocks.size();
            reader_.read(blocks);
            all.resize(blocks.size());
            for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
            const std::uint8_t* bytes = contiguous(all, [&](std::size_t i) { return reader_.block(i); });
            decode_into(ctx_, bytes, blocks.size(), scratch_, 0);
            stats_.blocks_decoded += blocks.size();
            std::size_t at = 0;
            for (std::size_t i = 0; i < blocks.size(); ++i) {
                const std::uint32_t n = block_flags(h_, bytes + i * bb).point_count;
                const std::uint64_t f = fibers[i];
                auto point = [&](std::size_t k) { return Vec3f{scratch_[3 * k], scratch_[3 * k + 1], scratch_[3 * k + 2]}; };
                if (blocks[i] == file_.first_block(f)) end_points[f][0] = point(at);
                if (blocks[i] + 1 == file_.first_block(f) + file_.block_count(f)) end_points[f][1] = point(at + n - 1);
                at += n;
            }
        }
        for (std::uint64_t f = 0; f < h_.fibers; ++f) {
            if (!keep_[f]) continue;
            if (file_.block_count(f) == 0) {  // no points: no end meets a region
                keep_[f] = q_.include.empty();
                continue;
            }
            const auto& e = end_points[f];
            auto met = [&](const Region& r) { return r.contains(e[0]) || r.contains(e[1]); };
            keep_[f] = std::all_of(q_.include.begin(), q_.include.end(), met) &&
                       std::none_of(q_.exclude.begin(), q_.exclude.end(), met);
        }
    }

    // skip / number over the kept fibers that have points, in file order.
    void skip_and_number() {
        if (q_.skip == 0 && !q_.number) return;
        std::uint64_t seen = 0;
        for (std::uint64_t f = 0; f < h_.fibers; ++f) {
            if (!keep_[f] || file_.block_count(f) == 0) continue;
            const std::uint64_t i = seen++;
            keep_[f] = i >= q_.skip && (!q_.number || i - q_.skip < *q_.number);
        }
    }

    // Pass 3's settings and the filters from the index, for the whole pass.
    struct BlockPass {
        bool blocks_mode = false, cull = false, include_tests = false;
        std::optional<LevelOfDetail> lod;
        Frustum frustum{};
        std::optional<Bits> only;  // candidate blocks (none: every block of a kept fiber)
        Bits exclude_near, include_inside;
        // Point tests needed: near an include region but not wholly inside
        // one, or near an exclude region.
        bool include_test(const std::vector<Region>& include, std::uint64_t b) const {
            return blocks_mode && !include.empty() && !has_bit(include_inside, b);
        }
        bool exclude_test(std::uint64_t b) const { return blocks_mode && !exclude_near.empty() && has_bit(exclude_near, b); }
    };
    enum BlockKind : std::uint8_t { dropped, fine, coarse };

    // Pass 3: the blocks of the kept fibers.
    void blocks(const std::function<void(const SelectedChunk&)>& sink) {
        const BlockPass pass = block_pass();
        RunWriter out(options_, sink, stats_, piece_blocks(h_, options_) * h_.points_per_block);
        CandidateBlocks candidates(file_, keep_, pass.only ? &*pass.only : nullptr);
        std::vector<std::uint32_t> blocks;
        std::vector<std::uint64_t> fibers;
        std::vector<BlockKind> kind;
        while (candidates.next(batch_blocks(h_), blocks, fibers)) {
            stats_.blocks_tested += blocks.size();
            // With a level of detail, the next block's first point may end a
            // segment; with include tests, it narrows the block's bound.
            read_with_next(blocks, fibers, pass.lod || pass.include_tests);
            classify_blocks(pass, blocks, kind);
            for (std::size_t i = 0, j; i < blocks.size(); i = j) {
                j = i + 1;
                if (kind[i] == coarse) write_coarse_block(pass, blocks, fibers, i, out);
                else if (kind[i] == fine) j = write_fine_blocks(pass, blocks, fibers, kind, i, out);
            }
        }
        out.finish();
    }

    // Candidate blocks from the index: near the frustum (grown by the
    // largest sphere radius) and, in blocks mode, near an include region.
    BlockPass block_pass() const {
        BlockPass p;
        p.blocks_mode = q_.roi_mode == RoiMode::blocks;
        p.cull = q_.view && q_.view->cull;
        if (q_.has_level_of_detail()) p.lod.emplace(q_.view->camera, *q_.view->lod, q_.view->lod_pixels);
        if (q_.view) p.frustum = frustum_from_camera(q_.view->camera);
        if (p.cull) {
            Bits f;
            const float margin = index_.max_sphere_radius() * (1 + 1e-5f) + 1e-3f;
            index_.blocks_starting_near_frustum(p.frustum, margin, f);
            f.resize((h_.blocks + 63) / 64, 0);
            p.only = std::move(f);
        }
        if (p.blocks_mode && !q_.include.empty()) {
            Bits inc = near_any(q_.include, &p.include_inside);
            if (p.only) and_bits(*p.only, inc);
            else p.only = std::move(inc);
        }
        if (p.blocks_mode && !q_.exclude.empty()) p.exclude_near = near_any(q_.exclude);
        p.include_tests = coarse_index_ && p.blocks_mode && !q_.include.empty();
        return p;
    }

    // Header tests: the block's sphere against the frustum, the level of
    // detail and, where its points would be tested, the include regions (the
    // index's boxes are coarser than the block's bound).
    void classify_blocks(const BlockPass& pass, const std::vector<std::uint32_t>& blocks, std::vector<BlockKind>& kind) {
        kind.assign(blocks.size(), fine);
        if (!q_.view && !pass.include_tests) return;
        spheres_of_read(need_.size());  // every header tested below, in one call (a call per block cost more)
        if (pass.cull) {
            in_frustum_.resize(need_.size());
            detail::spheres_in_frustum(pass.frustum, spheres_.data(), need_.size(), in_frustum_.data());
        }
        if (pass.include_tests) bounds_of_read(blocks.size(), false);  // exclude regions: tested on points
        for (std::size_t i = 0; i < blocks.size(); ++i) {
            const bool bound_test = pass.include_tests && pass.include_test(q_.include, blocks[i]);
            if (!q_.view && !bound_test) continue;
            const Sphere& s = spheres_[at_need_[i]];
            if (pass.cull && !in_frustum_[at_need_[i]]) {
                kind[i] = dropped;
                continue;
            }
            if (bound_test && !bound_meets_any(q_.include, include_meets_, i)) {
                kind[i] = dropped;
                continue;
            }
            if (pass.lod && pass.lod->coarse(s.center, s.radius)) kind[i] = coarse;
        }
    }

    bool region_test(const BlockPass& pass, std::uint64_t b) const {
        return pass.include_test(q_.include, b) || pass.exclude_test(b);
    }
    bool passes_regions(const BlockPass& pass, std::uint64_t b, const float* p, std::uint32_t n) const {
        if (pass.include_test(q_.include, b) && !any_point_in(q_.include, p, n)) return false;
        return !(pass.exclude_test(b) && any_point_in(q_.exclude, p, n));
    }

    // A coarse block: its first point, then the next block's first point or
    // the fiber's last point.
    void write_coarse_block(const BlockPass& pass, const std::vector<std::uint32_t>& blocks,
                            const std::vector<std::uint64_t>& fibers, std::size_t i, RunWriter& out) {
        const std::uint8_t* block = reader_.block(at_need_[i]);
        const std::uint32_t n = block_flags(h_, block).point_count;
        const bool last = next_at_need_[i] == SIZE_MAX;
        if (region_test(pass, blocks[i]) || (last && n > 1)) {
            decode_into(ctx_, block, 1, scratch_, 0);
            ++stats_.blocks_decoded;
            if (!passes_regions(pass, blocks[i], scratch_.data(), n)) return;
        }
        Vec3f end{};
        if (!last) end = first_point(h_, reader_.block(next_at_need_[i]));
        else if (n > 1) end = {scratch_[3 * (n - 1)], scratch_[3 * (n - 1) + 1], scratch_[3 * (n - 1) + 2]};
        out.coarse(fibers[i], blocks[i], first_point(h_, block), last && n < 2 ? nullptr : &end);
        out.maybe_flush();
    }

    // Fine blocks from i up to the next coarse one (dropped ones left out):
    // decoded straight into the output, a piece of up to piece_blocks() at a
    // time, then kept or dropped in place, and the chunk handed over when
    // full. Returns where the next coarse block (or the batch's end) is.
    std::size_t write_fine_blocks(const BlockPass& pass, const std::vector<std::uint32_t>& blocks,
                                  const std::vector<std::uint64_t>& fibers, const std::vector<BlockKind>& kind,
                                  std::size_t i, RunWriter& out) {
        segment_.assign(1, i);
        bool test = region_test(pass, blocks[i]);
        std::size_t j = i + 1;
        for (; j < blocks.size() && kind[j] != coarse; ++j)
            if (kind[j] == fine) segment_.push_back(j), test |= region_test(pass, blocks[j]);
        if (!options_.points && !test) {
            for (std::size_t k : segment_) out.fine(fibers[k], blocks[k], 0, block_flags(h_, reader_.block(at_need_[k])).point_count);
            out.maybe_flush();
            return j;
        }
        const std::span<const std::size_t> all(segment_);
        const std::size_t piece = piece_blocks(h_, options_);
        for (std::size_t first = 0; first < all.size(); first += piece)
            write_fine_piece(pass, blocks, fibers, all.subspan(first, std::min(piece, all.size() - first)), out);
        return j;
    }

    // Fine blocks blocks[piece[0]], blocks[piece[1]], ... decoded with one
    // call at the output's frontier.
    void write_fine_piece(const BlockPass& pass, const std::vector<std::uint32_t>& blocks,
                          const std::vector<std::uint64_t>& fibers, std::span<const std::size_t> piece, RunWriter& out) {
        const std::uint8_t* bytes = contiguous(piece, [&](std::size_t k) { return reader_.block(at_need_[k]); });
        out.break_unless_continues(fibers[piece[0]], blocks[piece[0]]);
        const std::size_t base = out.frontier();
        const std::size_t decoded = decode_into(ctx_, bytes, piece.size(), out.buffer(), base);
        stats_.blocks_decoded += piece.size();
        std::size_t at = base;
        for (std::size_t s = 0; s < piece.size(); ++s) {
            const std::size_t k = piece[s];
            const std::uint32_t n = block_flags(h_, bytes + s * h_.block_bytes()).point_count;
            if (passes_regions(pass, blocks[k], &out.buffer()[3 * at], n)) out.fine(fibers[k], blocks[k], at, n);
            at += n;
        }
        out.advance(decoded);
        out.maybe_flush();
    }

    // Reads `blocks` and, with `with_next`, the next block of each in its
    // fiber: at_need_[i] is block i's place among the reader's blocks,
    // next_at_need_[i] its successor's (SIZE_MAX: not read).
    void read_with_next(const std::vector<std::uint32_t>& blocks, const std::vector<std::uint64_t>& fibers,
                        bool with_next) {
        need_.clear(), at_need_.assign(blocks.size(), 0), next_at_need_.assign(blocks.size(), SIZE_MAX);
        for (std::size_t i = 0; i < blocks.size(); ++i) {
            if (need_.empty() || need_.back() != blocks[i]) need_.push_back(blocks[i]);
            at_need_[i] = need_.size() - 1;
            const std::uint64_t next = std::uint64_t(blocks[i]) + 1;
            if (with_next && next < file_.block_end(fibers[i] + 1)) {
                need_.push_back(std::uint32_t(next));  // the next candidate, if it is that block, reuses it
                next_at_need_[i] = need_.size() - 1;
            }
        }
        reader_.read(need_);
    }

    // bounds_[i]: the bound of candidate i of the read batch (block_bound:
    // its sphere, narrowed by the next block's), i < count; for each sphere
    // include region (and exclude region, with_exclude), whether each bound
    // may meet it, in vectors (bound_meets reads them; other regions are
    // tested where asked).
    void bounds_of_read(std::size_t count, bool with_exclude) {
        bounds_.compute(spheres_.data(), at_need_.data(), next_at_need_.data(), count, index_.max_join());
        auto meets_of = [&](const std::vector<Region>& regions, std::vector<std::vector<std::uint8_t>>& meets) {
            meets.resize(regions.size());
            for (std::size_t k = 0; k < regions.size(); ++k)
                if (regions[k].shape == Region::Shape::sphere) {
                    meets[k].resize(count);
                    bounds_.may_meet(regions[k], meets[k].data());
                }
        };
        meets_of(q_.include, include_meets_);
        if (with_exclude) meets_of(q_.exclude, exclude_meets_);
    }
    bool bound_meets(const Region& r, const std::vector<std::uint8_t>& sphere_meets, std::size_t i) const {
        return r.shape == Region::Shape::sphere ? sphere_meets[i] != 0 : detail::bound_may_meet(r, bounds_[i]);
    }
    bool bound_meets_any(const std::vector<Region>& regions, const std::vector<std::vector<std::uint8_t>>& meets,
                         std::size_t i) const {
        for (std::size_t k = 0; k < regions.size(); ++k)
            if (bound_meets(regions[k], meets[k], i)) return true;
        return false;
    }

    // spheres_[k]: the view sphere of the reader's block k, for k < count.
    void spheres_of_read(std::size_t count) {
        block_pointers_.resize(count);
        for (std::size_t k = 0; k < count; ++k) block_pointers_[k] = reader_.block(k);
        spheres_.resize(count);
        detail::block_spheres(h_, block_pointers_.data(), count, spheres_.data());
    }

    // The blocks block_of(items[0]), block_of(items[1]), ... one after the
    // other in memory: where they are when they follow each other in the
    // reader's buffer (e.g. every block of the kept fibers), else copied into
    // staging_ (76 bytes a block, against 720 decoded).
    template <class BlockOf>
    const std::uint8_t* contiguous(std::span<const std::size_t> items, const BlockOf& block_of) {
        const std::uint32_t bb = h_.block_bytes();
        const std::uint8_t* const first = block_of(items[0]);
        bool in_place = true;
        for (std::size_t s = 1; s < items.size() && in_place; ++s) in_place = block_of(items[s]) == first + s * bb;
        if (in_place) return first;
        staging_.resize(items.size() * bb);
        for (std::size_t s = 0; s < items.size(); ++s) std::memcpy(&staging_[s * bb], block_of(items[s]), bb);
        return staging_.data();
    }

    const FftFile& file_;
    const BlockIndex& index_;
    const Query& q_;
    const SelectOptions& options_;
    const FftHeader& h_;
    DecodeContext ctx_;
    detail::BlockBatchReader reader_;
    const bool trust_inside_;
    const bool coarse_index_;
    std::vector<std::uint8_t> keep_;
    detail::UninitializedVector<float> scratch_;  // decoded points that are tested, not output
    std::vector<std::uint8_t> staging_;
    std::vector<std::size_t> segment_;
    std::vector<const std::uint8_t*> block_pointers_;
    std::vector<Sphere> spheres_;  // of the blocks read, in reading order
    std::vector<std::uint8_t> in_frustum_;  // per block read: its sphere meets the view frustum
    detail::BlockBounds bounds_;    // of the candidates read (bounds_of_read)
    std::vector<std::vector<std::uint8_t>> include_meets_, exclude_meets_;  // per sphere region: bound i may meet it
    std::vector<std::uint32_t> need_;                   // blocks read (read_with_next)
    std::vector<std::size_t> at_need_, next_at_need_;   // a candidate's place among them, its successor's
    SelectionStats stats_;
};

}  // namespace

SelectionStats select(const FftFile& file, const BlockIndex& index, const Query& query,
                      const std::function<void(const SelectedChunk&)>& sink, const SelectOptions& options) {
    return Selector(file, index, query, options).run(sink);
}

Streamlines select_streamlines(const FftFile& file, const BlockIndex& index, const Query& query,
                               std::vector<SelectedRun>* runs, SelectionStats* stats) {
    Streamlines all;
    if (runs) runs->clear();
    const SelectionStats s = select(file, index, query, [&](const SelectedChunk& c) {
        for (std::size_t i = 0; i < c.size(); ++i) {
            all.xyz.insert(all.xyz.end(), c.xyz_of(i), c.xyz_of(i) + 3 * c.points_of(i));
            all.offsets.push_back(all.offsets.back() + c.points_of(i));
        }
        if (runs) runs->insert(runs->end(), c.runs.begin(), c.runs.end());
    });
    if (stats) *stats = s;
    return all;
}

std::vector<SelectedRun> select_runs(const FftFile& file, const BlockIndex& index, const Query& query,
                                     SelectionStats* stats) {
    std::vector<SelectedRun> runs;
    SelectOptions o;
    o.points = false;
    const SelectionStats s = select(
        file, index, query, [&](const SelectedChunk& c) { runs.insert(runs.end(), c.runs.begin(), c.runs.end()); }, o);
    if (stats) *stats = s;
    return runs;
}

}  // namespace fiblet
