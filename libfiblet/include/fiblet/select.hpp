// fiblet — selective decoding: decode only what a scene or an analysis
// needs, by fiber subset, region of interest, view frustum and level of
// detail. Queries compose (every criterion must hold); the block index
// (block_index.hpp) keeps rejected blocks from being read.
//
// Semantics, each checked in tests against "decode everything, then filter":
//  - fiber subset: IDs are the fibers' positions in the file (0-based);
//    length is (points - 1) * step, the decoded fiber's length (like
//    tckedit -minlength / -maxlength, both bounds inclusive); the random
//    subset keeps fiber f when in_random_subset(f, fraction, seed).
//  - regions (fibers mode, MRtrix3 tckedit -include / -exclude): a fiber is
//    kept when, for every include region, one of its points lies inside it,
//    and none of its points lies inside any exclude region. Image masks
//    test the voxel nearest to each point, as tckedit does.
//    With ends_only (tckedit -ends_only) only each fiber's first and last
//    points are tested against the regions.
//  - inverse (tckedit -inverse): the fibers that fail at least one of the
//    fiber criteria above (IDs, length, random subset, fibers-mode regions)
//    are kept instead; the view still applies to their blocks.
//  - skip / number (tckedit -skip / -number): of the fibers kept, in file
//    order, the first `skip` are left out and at most `number` of the rest
//    kept (fibers without points, never output, do not count).
//  - regions (blocks mode): a block is kept when one of its points lies
//    inside some include region (or there is none) and none lies inside an
//    exclude region; the fiber-level criteria still apply first.
//  - view: with culling, a block is kept when its bounding sphere (view.hpp,
//    as the GPU viewer tests it) meets the camera's frustum; with a level of
//    detail, a kept block whose sphere projects under lod_pixels becomes one
//    segment from its first point to the next block's first point (the
//    fiber's last point for its last block).
// Kept blocks that follow each other in a fiber form one output streamline
// (a "run"); whole-fiber queries give one run per kept fiber.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fiblet/block_index.hpp"
#include "fiblet/decode.hpp"
#include "fiblet/fft_file.hpp"
#include "fiblet/image_mask.hpp"
#include "fiblet/view.hpp"

namespace fiblet {

// A region of interest: a sphere (inside when |p - center| <= radius), a
// box (inside when min <= p <= max on every axis), world mm, or an image
// mask (fiblet/image_mask.hpp: tckedit's rule for images).
struct Region {
    enum class Shape { sphere, box, mask };
    Shape shape = Shape::sphere;
    Vec3f center{};
    float radius = 0;
    Aabb box{};
    std::shared_ptr<const ImageMask> mask;

    static Region sphere(Vec3f center, float radius);
    static Region box_between(Vec3f min, Vec3f max);
    static Region image(std::shared_ptr<const ImageMask> mask);
    bool contains(Vec3f p) const {
        if (shape == Shape::mask) return mask->contains(p);
        if (shape == Shape::sphere) {
            const float dx = p.x - center.x, dy = p.y - center.y, dz = p.z - center.z;
            return dx * dx + dy * dy + dz * dz <= radius * radius;
        }
        return p.x >= box.min.x && p.x <= box.max.x && p.y >= box.min.y && p.y <= box.max.y && p.z >= box.min.z &&
               p.z <= box.max.z;
    }
};

enum class RoiMode { fibers, blocks };

// Fibers first..last, inclusive.
struct FiberRange {
    std::uint64_t first = 0, last = 0;
};

struct ViewSelection {
    Camera camera;
    bool cull = true;               // frustum culling of the blocks' spheres
    std::optional<Viewport> lod;    // level of detail, when set
    float lod_pixels = kDefaultLodPixels;
};

struct Query {
    std::vector<FiberRange> fibers;  // empty: every fiber
    std::optional<double> min_length_mm, max_length_mm;
    std::optional<double> random_fraction;  // in [0, 1]
    std::uint64_t random_seed = 0;
    std::vector<Region> include, exclude;
    RoiMode roi_mode = RoiMode::fibers;
    bool ends_only = false;               // fibers-mode regions test each fiber's end points only
    bool inverse = false;                 // keep the fibers failing some fiber criterion (fibers mode)
    std::uint64_t skip = 0;               // kept fibers left out first, in file order
    std::optional<std::uint64_t> number;  // then at most this many kept
    std::optional<ViewSelection> view;

    bool has_level_of_detail() const { return view && view->lod; }
};

// The random subset: keeps fiber f when splitmix64(seed ^ splitmix64(f)),
// as a fraction of 2^64, is below `fraction` (independent of the order and of
// the other criteria, reproducible everywhere).
bool in_random_subset(std::uint64_t fiber, double fraction, std::uint64_t seed);
std::uint64_t splitmix64(std::uint64_t x);

// Length in mm of a decoded fiber of `points` points.
double fiber_length_mm(const FftHeader& h, std::uint64_t points);

// One output streamline: blocks [first_block, first_block + block_count) of
// a source fiber, `coarse_blocks` of them drawn as one segment each.
struct SelectedRun {
    std::uint64_t fiber = 0;
    std::uint64_t first_block = 0;
    std::uint32_t block_count = 0;
    std::uint32_t coarse_blocks = 0;
};

struct SelectionStats {
    std::uint64_t fibers = 0;          // source fibers with at least one run
    std::uint64_t runs = 0;            // output streamlines
    std::uint64_t blocks = 0;          // blocks kept (fine + coarse)
    std::uint64_t coarse_blocks = 0;
    std::uint64_t points = 0;          // points output
    std::uint64_t blocks_tested = 0;   // candidates the index let through, tested by header or points (all passes)
    std::uint64_t blocks_read = 0;     // blocks read or accessed in the mapping (all passes)
    std::uint64_t blocks_decoded = 0;  // blocks decoded (all passes)
};

// A chunk of output, valid during the sink call: streamline i comes from
// runs[i] and has the points_of(i) points that start at xyz_of(i) (xyz
// triplets, world mm). Streamlines lie in order in `xyz`, possibly with
// unused points between them (a rejected block's), so that nothing is moved
// after decoding; first/count are empty when points were not asked for.
struct SelectedChunk {
    std::span<const float> xyz;
    std::span<const std::uint64_t> first, count;  // per streamline, in points
    std::span<const SelectedRun> runs;
    std::uint64_t points = 0;  // sum of count

    std::size_t size() const { return runs.size(); }
    std::uint64_t point_count() const { return points; }
    std::uint64_t points_of(std::size_t i) const { return count[i]; }
    const float* xyz_of(std::size_t i) const { return xyz.data() + 3 * first[i]; }
};

struct SelectOptions {
    bool points = true;                       // decode and output points
    // Points per chunk handed to the sink: a chunk goes out once it holds
    // this many, and blocks are decoded about this many points at a time.
    // 2^15 points (384 KB) keep the decoder writing into the same 1.2 MB and
    // the sink reading points still in cache (docs/select.md, "Chunks").
    std::size_t chunk_points = 1u << 15;
    // Copy the candidate blocks out of a memory mapping of the file
    // (FftFile::read_blocks_mapped: those blocks only, no system call per
    // block) instead of reading spans of the file with pread(), small gaps
    // included. A file that shrinks meanwhile is Error{fft_format} either
    // way; off only to compare the two (docs/select.md).
    bool map_file = true;
};

// Runs a query, handing the output to `sink` in file order, a chunk of whole
// runs at a time (bounded memory). Output is made of runs of blocks, so a
// fiber without points (an empty streamline of the .tck, kept by compress)
// is never part of it. Throws Error{invalid_argument} on a bad
// query, Error{fft_format} on a malformed block.
SelectionStats select(const FftFile& file, const BlockIndex& index, const Query& query,
                      const std::function<void(const SelectedChunk&)>& sink, const SelectOptions& options = {});

// The whole output in memory.
Streamlines select_streamlines(const FftFile& file, const BlockIndex& index, const Query& query,
                               std::vector<SelectedRun>* runs = nullptr, SelectionStats* stats = nullptr);
// The runs only (points are decoded only where a region test needs them).
std::vector<SelectedRun> select_runs(const FftFile& file, const BlockIndex& index, const Query& query,
                                     SelectionStats* stats = nullptr);

}  // namespace fiblet
