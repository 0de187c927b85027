// The query executor. Three passes, each touching only what it must:
//   1. fiber criteria (IDs, length, random subset): no I/O, the index knows
//      every fiber's point count;
//   2. fibers-mode regions: the blocks near a region (from the index) are
//      decoded and their points tested, which decides whole fibers;
//   3. the blocks of the kept fibers that the view / blocks-mode regions may
//      keep (from the index) are read, tested on their header (sphere, level
//      of detail) or points, decoded and handed out as runs.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>

#include "fiblet/error.hpp"
#include "fiblet/select.hpp"
#include "select/block_batch_reader.hpp"
#include "select/block_decoder.hpp"
#include "select/query_checks.hpp"

namespace fiblet {

namespace {

using Bits = std::vector<std::uint64_t>;
constexpr std::size_t kBatchBlocks = 4096;

bool has_bit(const Bits& b, std::uint64_t i) { return (b[i >> 6] >> (i & 63)) & 1; }

void and_bits(Bits& a, const Bits& b) {
    for (std::size_t i = 0; i < a.size(); ++i) a[i] &= b[i];
}

// The fiber of each block, for blocks visited in ascending order.
class FiberCursor {
public:
    explicit FiberCursor(const FftFile& file) : file_(file) {}
    std::uint64_t fiber_of(std::uint64_t block) {
        while (file_.block_end(fiber_ + 1) <= block) ++fiber_;
        return fiber_;
    }

private:
    const FftFile& file_;
    std::uint64_t fiber_ = 0;
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
            while (blocks.size() < max) {
                if (word_bits_ == 0) {
                    if (++word_ >= only_->size()) break;
                    word_bits_ = (*only_)[word_];
                    continue;
                }
                const std::uint64_t b = word_ * 64 + std::uint64_t(std::countr_zero(word_bits_));
                word_bits_ &= word_bits_ - 1;
                if (b >= nblocks) break;
                const std::uint64_t f = cursor_.fiber_of(b);
                if (keep_[f]) blocks.push_back(std::uint32_t(b)), fibers.push_back(f);
            }
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

// Blocks copied into one buffer and decoded with one call.
class DecodeStage {
public:
    explicit DecodeStage(const DecodeContext& ctx) : ctx_(ctx), bb_(ctx.header.block_bytes()) {}
    void clear() { raw_.clear(), first_point_.clear(); }
    std::size_t add(const std::uint8_t* block) {
        raw_.insert(raw_.end(), block, block + bb_);
        first_point_.push_back(0);
        return first_point_.size() - 1;
    }
    std::size_t size() const { return first_point_.size(); }
    void decode() {
        const std::size_t n = size();
        std::size_t total = count_block_points(ctx_, raw_.data(), n);
        xyz_.resize(3 * total);
        detail::decode_selected_blocks(ctx_, raw_.data(), n, xyz_.data());
        std::size_t at = 0;
        for (std::size_t i = 0; i < n; ++i) first_point_[i] = at, at += BlockView{&raw_[i * bb_]}.point_count();
    }
    const float* points(std::size_t i) const { return &xyz_[3 * first_point_[i]]; }

private:
    const DecodeContext& ctx_;
    std::uint32_t bb_;
    std::vector<std::uint8_t> raw_;
    std::vector<std::size_t> first_point_;
    std::vector<float> xyz_;
};

bool any_point_in(const Region& r, const float* p, std::uint32_t n) {
    for (std::uint32_t k = 0; k < n; ++k, p += 3)
        if (r.contains({p[0], p[1], p[2]})) return true;
    return false;
}

bool any_point_in(const std::vector<Region>& regions, const float* p, std::uint32_t n) {
    for (std::uint32_t k = 0; k < n; ++k, p += 3)
        for (const Region& r : regions)
            if (r.contains({p[0], p[1], p[2]})) return true;
    return false;
}

Vec3f first_point(const FftHeader& h, const std::uint8_t* block) {
    const auto a = BlockView{block}.anchors_normalized();
    return h.to_world(a[0], a[1], a[2]);
}

// Assembles kept blocks into runs and hands chunks of them to the sink.
class RunWriter {
public:
    RunWriter(const SelectOptions& o, const std::function<void(const SelectedChunk&)>& sink, SelectionStats& stats)
        : options_(o), sink_(sink), stats_(stats) {}

    // A fine block with its n points (points may be null when not output).
    void fine(std::uint64_t fiber, std::uint64_t block, const float* points, std::uint32_t n) {
        extend(fiber, block);
        if (options_.points) append(points, n);
        stats_.points += n;
        has_end_ = false;
    }
    // A coarse block: its first point now, `end` when the run stops after it.
    void coarse(std::uint64_t fiber, std::uint64_t block, Vec3f first, const Vec3f* end) {
        extend(fiber, block);
        ++run_.coarse_blocks, ++stats_.coarse_blocks;
        const float p[3] = {first.x, first.y, first.z};
        if (options_.points) append(p, 1);
        ++stats_.points;
        has_end_ = end != nullptr;
        if (end) end_ = *end;
    }
    void finish() {
        close();
        if (!chunk_.runs.empty()) flush();
    }

private:
    void extend(std::uint64_t fiber, std::uint64_t block) {
        if (open_ && (run_.fiber != fiber || run_.first_block + run_.block_count != block)) close();
        if (!open_) {
            if (fiber != last_fiber_) ++stats_.fibers, last_fiber_ = fiber;
            run_ = {fiber, block, 0, 0};
            open_ = true;
        }
        ++run_.block_count, ++stats_.blocks;
    }
    void append(const float* p, std::uint32_t n) { chunk_.lines.xyz.insert(chunk_.lines.xyz.end(), p, p + 3 * n); }
    void close() {
        if (!open_) return;
        if (has_end_) {
            const float p[3] = {end_.x, end_.y, end_.z};
            if (options_.points) append(p, 1);
            ++stats_.points;
            has_end_ = false;
        }
        open_ = false;
        ++stats_.runs;
        chunk_.runs.push_back(run_);
        if (options_.points) chunk_.lines.offsets.push_back(chunk_.lines.xyz.size() / 3);
        if (chunk_.lines.xyz.size() / 3 >= options_.chunk_points || chunk_.runs.size() >= options_.chunk_points)
            flush();
    }
    void flush() {
        sink_(chunk_);
        chunk_.lines.xyz.clear();
        chunk_.lines.offsets.assign(1, 0);
        chunk_.runs.clear();
    }

    const SelectOptions& options_;
    const std::function<void(const SelectedChunk&)>& sink_;
    SelectionStats& stats_;
    SelectedChunk chunk_;
    SelectedRun run_;
    bool open_ = false, has_end_ = false;
    Vec3f end_{};
    std::uint64_t last_fiber_ = ~std::uint64_t{0};
};

class Selector {
public:
    Selector(const FftFile& file, const BlockIndex& index, const Query& q, const SelectOptions& o)
        : file_(file), index_(index), q_(q), options_(o), h_(file.header()), ctx_(h_), reader_(file) {
        if (index.blocks() != h_.blocks || index.fibers() != h_.fibers)
            throw Error(Errc::invalid_argument, file.path() + ": the block index belongs to another file");
        detail::check_query(q);
    }

    SelectionStats run(const std::function<void(const SelectedChunk&)>& sink) {
        fiber_criteria();
        if (q_.roi_mode == RoiMode::fibers && !(q_.include.empty() && q_.exclude.empty())) fiber_regions();
        blocks(sink);
        stats_.blocks_read = reader_.blocks_read();
        return stats_;
    }

private:
    Bits near(const Region& r) const {
        Bits bits;
        if (r.shape == Region::Shape::sphere)
            index_.blocks_near_sphere(r.center, r.radius, bits);
        else
            index_.blocks_near_box(r.box, bits);
        bits.resize((h_.blocks + 63) / 64, 0);
        return bits;
    }
    Bits near_any(const std::vector<Region>& regions) const {
        Bits all((h_.blocks + 63) / 64, 0);
        for (const Region& r : regions) {
            const Bits b = near(r);
            for (std::size_t i = 0; i < all.size(); ++i) all[i] |= b[i];
        }
        return all;
    }

    // Pass 1: IDs, length, random subset.
    void fiber_criteria() {
        const std::uint64_t n = h_.fibers;
        keep_.assign(n, q_.fibers.empty() ? 1 : 0);
        for (const FiberRange& r : q_.fibers)
            for (std::uint64_t f = r.first; f <= std::min(r.last, n ? n - 1 : 0) && f < n; ++f) keep_[f] = 1;
        for (std::uint64_t f = 0; f < n; ++f) {
            if (!keep_[f]) continue;
            const double len = fiber_length_mm(h_, index_.fiber_points(f));
            if ((q_.min_length_mm && len < *q_.min_length_mm) || (q_.max_length_mm && len > *q_.max_length_mm) ||
                (q_.random_fraction && !in_random_subset(f, *q_.random_fraction, q_.random_seed)))
                keep_[f] = 0;
        }
    }

    // Pass 2 (fibers mode): a fiber must meet every include region and no
    // exclude region. Only blocks the index puts near a region are decoded.
    void fiber_regions() {
        const std::size_t k_inc = q_.include.size();
        std::vector<Bits> inc(k_inc);
        for (std::size_t k = 0; k < k_inc; ++k) inc[k] = near(q_.include[k]);
        const Bits exc = near_any(q_.exclude);
        const std::uint64_t all = k_inc == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << k_inc) - 1;

        // Fibers with no block near some include region fail without decoding.
        std::vector<std::uint64_t> may_meet(h_.fibers, 0), met(h_.fibers, 0);
        for (std::size_t k = 0; k < k_inc; ++k) {
            FiberCursor cursor(file_);
            for (std::size_t w = 0; w < inc[k].size(); ++w)
                for (std::uint64_t bits = inc[k][w]; bits; bits &= bits - 1) {
                    const std::uint64_t b = w * 64 + std::uint64_t(std::countr_zero(bits));
                    may_meet[cursor.fiber_of(b)] |= std::uint64_t{1} << k;
                }
        }
        for (std::uint64_t f = 0; f < h_.fibers; ++f)
            if (may_meet[f] != all) keep_[f] = 0;

        Bits to_test = exc;
        for (const Bits& b : inc)
            for (std::size_t i = 0; i < to_test.size(); ++i) to_test[i] |= b[i];
        std::vector<std::uint8_t> excluded(h_.fibers, 0);
        CandidateBlocks candidates(file_, keep_, &to_test);
        std::vector<std::uint32_t> blocks;
        std::vector<std::uint64_t> fibers;
        DecodeStage stage(ctx_);
        while (candidates.next(kBatchBlocks, blocks, fibers)) {
            reader_.read(blocks);
            stage.clear();
            for (std::size_t i = 0; i < blocks.size(); ++i) stage.add(reader_.block(i));
            stage.decode();
            stats_.blocks_decoded += blocks.size();
            for (std::size_t i = 0; i < blocks.size(); ++i) {
                const std::uint64_t f = fibers[i], b = blocks[i];
                if (excluded[f]) continue;
                const float* p = stage.points(i);
                const std::uint32_t n = BlockView{reader_.block(i)}.point_count();
                for (std::size_t k = 0; k < k_inc; ++k)
                    if (!(met[f] >> k & 1) && has_bit(inc[k], b) && any_point_in(q_.include[k], p, n))
                        met[f] |= std::uint64_t{1} << k;
                if (!q_.exclude.empty() && has_bit(exc, b) && any_point_in(q_.exclude, p, n)) excluded[f] = 1;
            }
        }
        for (std::uint64_t f = 0; f < h_.fibers; ++f)
            if (met[f] != all || excluded[f]) keep_[f] = 0;
    }

    // Pass 3: the blocks of the kept fibers.
    void blocks(const std::function<void(const SelectedChunk&)>& sink) {
        const bool blocks_mode = q_.roi_mode == RoiMode::blocks;
        const bool cull = q_.view && q_.view->cull;
        const bool lod = q_.has_level_of_detail();
        Frustum frustum{};
        if (q_.view) frustum = frustum_from_camera(q_.view->camera);

        // Candidate blocks from the index: near the frustum (grown by the
        // largest sphere radius) and, in blocks mode, near an include region.
        std::optional<Bits> only;
        if (cull) {
            Bits f;
            const float margin = index_.max_sphere_radius() * (1 + 1e-5f) + 1e-3f;
            index_.blocks_near_frustum(frustum, margin, f);
            f.resize((h_.blocks + 63) / 64, 0);
            only = std::move(f);
        }
        Bits exc;
        if (blocks_mode && !q_.include.empty()) {
            Bits inc = near_any(q_.include);
            if (only) and_bits(*only, inc);
            else only = std::move(inc);
        }
        if (blocks_mode && !q_.exclude.empty()) exc = near_any(q_.exclude);

        RunWriter out(options_, sink, stats_);
        CandidateBlocks candidates(file_, keep_, only ? &*only : nullptr);
        std::vector<std::uint32_t> blocks, need;
        std::vector<std::uint64_t> fibers;
        std::vector<std::size_t> at_need, next_at_need, staged;
        enum Kind : std::uint8_t { dropped, fine, coarse };
        std::vector<Kind> kind;
        DecodeStage stage(ctx_);
        while (candidates.next(kBatchBlocks, blocks, fibers)) {
            // With a level of detail, the next block's first point may end a segment.
            need.clear(), at_need.assign(blocks.size(), 0), next_at_need.assign(blocks.size(), SIZE_MAX);
            for (std::size_t i = 0; i < blocks.size(); ++i) {
                if (need.empty() || need.back() != blocks[i]) need.push_back(blocks[i]);
                at_need[i] = need.size() - 1;
                const std::uint64_t next = std::uint64_t(blocks[i]) + 1;
                if (lod && next < file_.block_end(fibers[i] + 1)) {
                    need.push_back(std::uint32_t(next));  // the next candidate, if it is that block, reuses it
                    next_at_need[i] = need.size() - 1;
                }
            }
            reader_.read(need);

            // Header tests, then one decode call for the blocks whose points are needed.
            kind.assign(blocks.size(), dropped);
            staged.assign(blocks.size(), SIZE_MAX);
            stage.clear();
            for (std::size_t i = 0; i < blocks.size(); ++i) {
                const std::uint8_t* block = reader_.block(at_need[i]);
                kind[i] = fine;
                if (q_.view) {
                    const Sphere s = block_bounding_sphere(h_, block);
                    if (cull && !sphere_intersects_frustum(frustum, s.center, s.radius)) {
                        kind[i] = dropped;
                        continue;
                    }
                    if (lod && block_is_coarse(q_.view->camera, *q_.view->lod, s.center, s.radius, q_.view->lod_pixels))
                        kind[i] = coarse;
                }
                const bool region_test = blocks_mode && (!q_.include.empty() || (!exc.empty() && has_bit(exc, blocks[i])));
                const bool last_of_fiber = std::uint64_t(blocks[i]) + 1 == file_.block_end(fibers[i] + 1);
                const bool needs_points = region_test || (kind[i] == fine && options_.points) ||
                                          (kind[i] == coarse && last_of_fiber && BlockView{block}.point_count() > 1);
                if (needs_points) staged[i] = stage.add(block);
            }
            if (stage.size() > 0) stage.decode();
            stats_.blocks_decoded += stage.size();

            for (std::size_t i = 0; i < blocks.size(); ++i) {
                if (kind[i] == dropped) continue;
                const std::uint8_t* block = reader_.block(at_need[i]);
                const std::uint32_t n = BlockView{block}.point_count();
                const float* p = staged[i] == SIZE_MAX ? nullptr : stage.points(staged[i]);
                if (blocks_mode && p && (!q_.include.empty() || (!exc.empty() && has_bit(exc, blocks[i])))) {
                    const bool meets = q_.include.empty() || any_point_in(q_.include, p, n);
                    if (!meets || (!exc.empty() && has_bit(exc, blocks[i]) && any_point_in(q_.exclude, p, n)))
                        continue;
                }
                if (kind[i] == fine) {
                    out.fine(fibers[i], blocks[i], p, n);
                    continue;
                }
                // Coarse: first point, then the next block's first point or the fiber's last point.
                Vec3f end{};
                const Vec3f* end_ptr = nullptr;
                if (next_at_need[i] != SIZE_MAX) {
                    end = first_point(h_, reader_.block(next_at_need[i]));
                    end_ptr = &end;
                } else if (n > 1) {
                    end = {p[3 * (n - 1)], p[3 * (n - 1) + 1], p[3 * (n - 1) + 2]};
                    end_ptr = &end;
                }
                out.coarse(fibers[i], blocks[i], first_point(h_, block), end_ptr);
            }
        }
        out.finish();
    }

    const FftFile& file_;
    const BlockIndex& index_;
    const Query& q_;
    const SelectOptions& options_;
    const FftHeader& h_;
    DecodeContext ctx_;
    detail::BlockBatchReader reader_;
    std::vector<std::uint8_t> keep_;
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
        const std::uint64_t base = all.point_count();
        all.xyz.insert(all.xyz.end(), c.lines.xyz.begin(), c.lines.xyz.end());
        for (std::size_t i = 1; i < c.lines.offsets.size(); ++i) all.offsets.push_back(base + c.lines.offsets[i]);
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
