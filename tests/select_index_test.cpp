// The block index: every stored or computed box contains every point its
// block decodes to, candidate sets never miss a block with a point in the
// region, the stored chunk has the documented size within 1 % of the file,
// older versions (1, 2, 3) are still read, and malformed chunks are rejected
// with a clear error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <tuple>

#include "fiblet/block_index.hpp"
#include "fiblet/checksum.hpp"
#include "fiblet/compress.hpp"
#include "fiblet/error.hpp"
#include "fiblet/fft_subset.hpp"
#include "fiblet/select.hpp"
#include "select/block_bits.hpp"
#include "cli_runner.hpp"
#include "scoped_simd_loops.hpp"
#include "select_reference.hpp"
#include "test_util.hpp"

using namespace fiblet;
using namespace fiblet::test;

namespace {

// Files are compressed on first use (CTest runs every test in its own process).
class SelectIndex : public ::testing::Test {
protected:
    static void TearDownTestSuite() { dir_.reset(); }
    void SetUp() override {
        if (!shared_data_available()) GTEST_SKIP() << "shared test data not found";
    }
    static std::string work_file(const std::string& name) {
        if (!dir_) dir_ = std::make_unique<TempDir>();
        return dir_->file(name);
    }
    // The finer index (version 4) unless a test asks otherwise: most tests
    // here check its boxes; the default version 2 is checked by
    // CompressWritesVersionTwoByDefaultAndFourWithTheFineIndex and v2_file().
    static CompressOptions fine_index() {
        CompressOptions o;
        o.index_format = BlockIndexFormat::block_boxes;
        return o;
    }
    static std::string compressed(const std::string& tck, const std::string& name, CompressOptions o = fine_index()) {
        const std::string out = work_file(name);
        if (!std::filesystem::exists(out)) {
            o.threads = 2;
            // The 8-bit layout unless a test asks for 16 (the default gives small-sdstream 16 bits).
            if (!o.direction_bits) o.direction_bits = 8;
            compress_file(shared_data(tck), out, o);
        }
        return out;
    }
    static std::string fiblet_file() { return compressed("small-sdstream.tck", "sdstream.fft"); }
    static std::string dwi_file() { return compressed("dwi-small64d-ifod1.tck", "dwi.fft"); }
    // dwi-small64d-ifod1.tck as fiblet wrote it before version 3: a version-2
    // index, groups of 8 blocks (tests/index-v2/README.md).
    static std::string v2_file() { return std::string(FIBLET_TESTS_DIR) + "/index-v2/dwi-small64d-ifod1.fft"; }
    // The same as fiblet wrote it with --fine-index before version 4: a
    // version-3 index, range-coded (tests/index-v3/README.md).
    static std::string v3_file() { return std::string(FIBLET_TESTS_DIR) + "/index-v3/dwi-small64d-ifod1.fft"; }
    static inline std::unique_ptr<TempDir> dir_;
};

using detail::has_bit;

// `count` random region queries (seeded), every other one in blocks mode and
// (`with_views`) every third one with a camera, select through `index`
// exactly what the decode-everything reference keeps.
void expect_selections_match_brute_force(const FftFile& file, const BlockIndex& index, const DecodedFile& d,
                                         std::uint32_t seed, int count, bool with_views, const std::string& label) {
    QueryGenerator gen(d, seed);
    for (int i = 0; i < count; ++i) {
        Query q;
        q.include.push_back(gen.region());
        if (i % 2) q.roi_mode = RoiMode::blocks;
        if (with_views && i % 3 == 0) q.view = ViewSelection{gen.camera(), true, std::nullopt, 4.0f};
        std::vector<SelectedRun> runs;
        const Streamlines got = select_streamlines(file, index, q, &runs);
        expect_same_selection(reference_select(file, d, q), got, runs, label + " query " + std::to_string(i));
    }
}

void expect_boxes_hold_points(const FftFile& file, const BlockIndex& index, const DecodedFile& d) {
    ASSERT_EQ(index.blocks(), file.header().blocks);
    ASSERT_EQ(index.fibers(), file.header().fibers);
    for (std::uint64_t f = 0; f < index.fibers(); ++f)
        ASSERT_EQ(index.fiber_points(f), d.points.offsets[f + 1] - d.points.offsets[f]) << "fiber " << f;
    for (std::size_t b = 0; b < d.blocks.size(); ++b) {
        const Aabb box = index.block_box(b);
        for (std::uint32_t k = 0; k < d.blocks[b].points; ++k) {
            const Vec3f p = point_at(d, d.blocks[b].first_point + k);
            ASSERT_TRUE(box.min.x <= p.x && p.x <= box.max.x && box.min.y <= p.y && p.y <= box.max.y &&
                        box.min.z <= p.z && p.z <= box.max.z)
                << "block " << b << " point " << k;
        }
        ASSERT_LE(d.blocks[b].sphere.radius, index.max_sphere_radius()) << "block " << b;
    }
    // The file's bounds: the union of the blocks' boxes.
    const std::optional<Aabb> all = index.bounds();
    ASSERT_TRUE(all);
    Aabb expected = index.block_box(0);
    for (std::size_t b = 1; b < d.blocks.size(); ++b) {
        const Aabb box = index.block_box(b);
        expected.min = {std::min(expected.min.x, box.min.x), std::min(expected.min.y, box.min.y), std::min(expected.min.z, box.min.z)};
        expected.max = {std::max(expected.max.x, box.max.x), std::max(expected.max.y, box.max.y), std::max(expected.max.z, box.max.z)};
    }
    for (const auto& [got, want] : {std::pair{all->min, expected.min}, std::pair{all->max, expected.max}}) {
        EXPECT_EQ(got.x, want.x);
        EXPECT_EQ(got.y, want.y);
        EXPECT_EQ(got.z, want.z);
    }
}

TEST_F(SelectIndex, CompressStoresAnIndexWhoseBoxesHoldEveryPoint) {
    for (const std::string& path : {fiblet_file(), dwi_file()}) {
        const FftFile file(path);
        ASSERT_NE(file.find_chunk(kBlockIndexTag), nullptr);
        const BlockIndex index = BlockIndex::load(file);
        EXPECT_EQ(index.source(), BlockIndex::Source::chunk);
        expect_boxes_hold_points(file, index, decode_everything(file));
    }
}

TEST_F(SelectIndex, WithoutTheIndexTheFileIsSmallerAndTheIndexIsComputedOnLoad) {
    CompressOptions o;
    o.block_index = false;
    const FftFile bare(compressed("small-sdstream.tck", "sdstream-noindex.fft", o));
    const FftFile full(fiblet_file());
    ASSERT_EQ(bare.find_chunk(kBlockIndexTag), nullptr);
    EXPECT_EQ(bare.file_size() + 16 + full.find_chunk(kBlockIndexTag)->payload.size(), full.file_size());  // chunk header + payload
    EXPECT_EQ(bare.read_blocks(0, bare.header().blocks), full.read_blocks(0, full.header().blocks));
    const BlockIndex index = BlockIndex::load(bare);
    EXPECT_EQ(index.source(), BlockIndex::Source::decoded);
    expect_boxes_hold_points(bare, index, decode_everything(bare));
}

TEST_F(SelectIndex, ComputedIndexOfOfficialEncoderFilesHoldsEveryPoint) {
    const FftFile file(shared_data("reference/small-sdstream.fft"));
    ASSERT_EQ(file.find_chunk(kBlockIndexTag), nullptr);
    const BlockIndex index = BlockIndex::load(file);
    EXPECT_EQ(index.source(), BlockIndex::Source::decoded);
    const DecodedFile d = decode_everything(file);
    expect_boxes_hold_points(file, index, d);
    // Computed boxes are exact: each face touches a point.
    for (std::size_t b = 0; b < d.blocks.size(); b += 97) {
        float lo = INFINITY;
        for (std::uint32_t k = 0; k < d.blocks[b].points; ++k)
            lo = std::min(lo, point_at(d, d.blocks[b].first_point + k).x);
        EXPECT_EQ(index.block_box(b).min.x, lo);
    }
}

// The groups of a version-2 index: 8 blocks at a time from each fiber's
// first block, as the format says.
std::vector<std::pair<std::uint64_t, std::uint64_t>> index_groups(const FftFile& file, std::uint32_t g) {
    std::vector<std::pair<std::uint64_t, std::uint64_t>> groups;  // first block, end
    for (std::uint64_t f = 0; f < file.header().fibers; ++f)
        for (std::uint64_t b = file.first_block(f), e = b + file.block_count(f); b < e; b += g)
            groups.emplace_back(b, std::min<std::uint64_t>(b + g, e));
    return groups;
}

// The payload's box stream bytes (versions 3 and 4, formats/fft-index.md §1).
std::uint64_t stream_bytes(const std::vector<std::uint8_t>& p) {
    std::uint64_t n;
    std::memcpy(&n, &p[56], 8);
    return n;
}

TEST_F(SelectIndex, StoredBoxesBoundBlocksWithinACellOfTheirExactBoxes) {
    const FftFile file(fiblet_file());
    const BlockIndex stored = BlockIndex::load(file), exact = BlockIndex::compute(file);
    EXPECT_EQ(exact.groups(), exact.blocks());
    // The grid's cell is half a block's path (60 points at 0.1 mm: 3 mm):
    // every side of a block's stored box lies within a cell of its exact box.
    const FftHeader& h = file.header();
    const double cell = double(h.points_per_block) * double(h.step) * double(h.scaling) / 2;
    ASSERT_GT(cell, 2.9);
    ASSERT_LT(cell, 3.1);
    double grow = 0;
    for (std::uint64_t b = 0; b < stored.blocks(); ++b) {
        const Aabb u = exact.block_box(b), s = stored.block_box(b);
        for (float d : {u.min.x - s.min.x, u.min.y - s.min.y, u.min.z - s.min.z, s.max.x - u.max.x, s.max.y - u.max.y,
                        s.max.z - u.max.z}) {
            ASSERT_GE(d, 0.0f) << "block " << b;
            ASSERT_LT(d, cell * 1.01) << "block " << b;
            grow += d;
        }
    }
    EXPECT_LT(grow / double(6 * stored.blocks()), 0.6 * cell);  // about half a cell on average
}

// The stored index of a file written with BIDX version `version`: it loads
// as that version, its boxes hold every point, verify accepts it and it
// selects what brute force keeps.
BlockIndex expect_stored_index_sound(const FftFile& file, std::uint32_t version) {
    const TrailerChunk* c = file.find_chunk(kBlockIndexTag);
    EXPECT_NE(c, nullptr);
    if (c) {
        EXPECT_EQ(c->payload[0], version);
    }
    BlockIndex index = BlockIndex::load(file);
    EXPECT_EQ(index.source(), BlockIndex::Source::chunk);
    EXPECT_EQ(index.chunk_version(), version);
    const DecodedFile d = decode_everything(file);
    expect_boxes_hold_points(file, index, d);
    EXPECT_NO_THROW(verify_fft_file(file.path()));
    expect_selections_match_brute_force(file, index, d, 4, 12, true, file.path());
    return index;
}

TEST_F(SelectIndex, VersionTwoIndexesAreStillRead) {
    const FftFile file(v2_file());
    const BlockIndex index = expect_stored_index_sound(file, 2);
    EXPECT_EQ(index.groups(), index_groups(file, 8).size());
    // A group's box is given for each of its blocks.
    for (const auto& [b0, b1] : index_groups(file, 8))
        for (std::uint64_t b = b0 + 1; b < b1; ++b) ASSERT_EQ(index.block_box(b).min.x, index.block_box(b0).min.x);
}

TEST_F(SelectIndex, VersionThreeIndexesAreStillRead) {
    const FftFile file(v3_file());
    const BlockIndex index = expect_stored_index_sound(file, 3);
    // Its boxes are those version 4 stores for the same blocks (its own,
    // copied with a fresh index: every fiber one run): both quantize each
    // block's bounds on the same grid.
    const std::string copy = work_file("v3-reindexed.fft");
    write_fft_subset(file, select_runs(file, index, Query{}), copy, true, BlockIndexFormat::block_boxes);
    const FftFile v4(copy);
    const BlockIndex fine = BlockIndex::load(v4);
    ASSERT_EQ(fine.chunk_version(), 4u);
    ASSERT_EQ(v4.read_blocks(0, v4.header().blocks), file.read_blocks(0, file.header().blocks));
    for (std::uint64_t b = 0; b < index.blocks(); ++b) {
        const Aabb u = index.block_box(b), v = fine.block_box(b);
        ASSERT_TRUE(u.min.x == v.min.x && u.min.y == v.min.y && u.min.z == v.min.z && u.max.x == v.max.x &&
                    u.max.y == v.max.y && u.max.z == v.max.z)
            << "block " << b;
    }
}

// compress writes version 2 (quick to load) unless asked for the finer
// version 4; both select exactly what brute force keeps.
TEST_F(SelectIndex, CompressWritesVersionTwoByDefaultAndFourWithTheFineIndex) {
    const std::string coarse = compressed("dwi-small64d-ifod1.tck", "dwi-default.fft", CompressOptions{});
    for (const auto& [path, version] : {std::pair{coarse, 2u}, std::pair{dwi_file(), 4u}}) {
        const FftFile file(path);
        const BlockIndex index = BlockIndex::load(file);
        ASSERT_EQ(index.source(), BlockIndex::Source::chunk) << path;
        EXPECT_EQ(index.chunk_version(), version) << path;
        if (version == 2) {
            EXPECT_EQ(index.groups(), index_groups(file, 8).size()) << path;
        }
        const DecodedFile d = decode_everything(file);
        expect_boxes_hold_points(file, index, d);
        EXPECT_NO_THROW(verify_fft_file(file.path()));
        expect_selections_match_brute_force(file, index, d, 6, 12, true, path);
    }
}

// The CLI: --fine-index asks compress and extract -o x.fft for version 4;
// without it they write version 2.
TEST_F(SelectIndex, FineIndexFlagChoosesTheVersionCompressAndExtractWrite) {
    const std::string tck = shared_data("dwi-small64d-ifod1.tck");
    auto version_of = [](const std::string& path) { return BlockIndex::load(FftFile(path)).chunk_version(); };
    const std::string plain = work_file("cli-plain.fft"), fine = work_file("cli-fine.fft");
    ASSERT_EQ(test::run_cli("compress -q -f " + tck + " -o " + plain).status, 0);
    ASSERT_EQ(test::run_cli("compress -q -f --fine-index " + tck + " -o " + fine).status, 0);
    EXPECT_EQ(version_of(plain), 2u);
    EXPECT_EQ(version_of(fine), 4u);
    // info says which, read from the chunk without loading it (none: null).
    const std::string bare = work_file("cli-bare.fft");
    ASSERT_EQ(test::run_cli("compress -q -f --no-index " + tck + " -o " + bare).status, 0);
    for (const auto& [path, version] : {std::pair{plain, "2"}, std::pair{fine, "4"}, std::pair{bare, "null"}}) {
        const auto info = test::run_cli("info --json " + path);
        ASSERT_EQ(info.status, 0) << info.output;
        EXPECT_NE(info.output.find(std::string("\"block_index_version\": ") + version), std::string::npos) << info.output;
        EXPECT_EQ(BlockIndex::stored_version(FftFile(path)), version == std::string("null") ? std::nullopt
                                                                                           : std::optional(version_of(path)));
    }
    for (const std::string& from : {plain, fine}) {
        const std::string sub = work_file("cli-sub.fft"), sub_fine = work_file("cli-sub-fine.fft");
        const std::string region = " --include 0,0,0,30";
        ASSERT_EQ(test::run_cli("extract -q -f " + from + " -o " + sub + region).status, 0);
        ASSERT_EQ(test::run_cli("extract -q -f --fine-index " + from + " -o " + sub_fine + region).status, 0);
        EXPECT_EQ(version_of(sub), 2u) << from;
        EXPECT_EQ(version_of(sub_fine), 4u) << from;
        EXPECT_EQ(FftFile(sub).header().blocks, FftFile(sub_fine).header().blocks) << from;
        EXPECT_GT(FftFile(sub).header().blocks, 0u) << from;
    }
}

TEST_F(SelectIndex, EveryPointLiesInItsBlocksViewSphere) {
    // Selections narrow an index group down to its blocks with this sphere
    // (from the block's header): it must hold every decoded point.
    for (const std::string& path : {fiblet_file(), dwi_file(), shared_data("reference/small-ifod1.fft")}) {
        const FftFile file(path);
        const DecodedFile d = decode_everything(file);
        for (std::size_t b = 0; b < d.blocks.size(); ++b) {
            const Sphere& s = d.blocks[b].sphere;
            for (std::uint32_t k = 0; k < d.blocks[b].points; ++k) {
                const Vec3f p = point_at(d, d.blocks[b].first_point + k);
                const double dx = p.x - s.center.x, dy = p.y - s.center.y, dz = p.z - s.center.z;
                ASSERT_LE(std::sqrt(dx * dx + dy * dy + dz * dz), double(s.radius)) << path << " block " << b;
            }
        }
    }
}

TEST_F(SelectIndex, StoredJoinBoundsTheJumpBetweenBlocksOfAFiber) {
    // Selections bound a block by the segment to the next block's first
    // point (docs/select.md): the stored bound must hold every jump, and be
    // about one step (not a loose number that would make it useless).
    for (const std::string& path : {fiblet_file(), dwi_file()}) {
        const FftFile file(path);
        const BlockIndex index = BlockIndex::load(file);
        const DecodedFile d = decode_everything(file);
        double largest = 0;
        for (std::size_t b = 0; b + 1 < d.blocks.size(); ++b) {
            if (d.blocks[b].last_of_fiber) continue;
            const Vec3f e = point_at(d, d.blocks[b].first_point + d.blocks[b].points - 1);
            const Vec3f s = point_at(d, d.blocks[b + 1].first_point);
            const double dx = double(s.x) - e.x, dy = double(s.y) - e.y, dz = double(s.z) - e.z;
            largest = std::max(largest, std::sqrt(dx * dx + dy * dy + dz * dz));
        }
        EXPECT_GE(double(index.max_join()), largest) << path;
        EXPECT_LT(double(index.max_join()), largest * 1.001 + 1e-6) << path;
        const FftHeader& h = file.header();
        EXPECT_LT(double(index.max_join()), 3.0 * double(h.step) * double(h.scaling)) << path;
    }
}

TEST_F(SelectIndex, ChunkHasTheDocumentedSizeWithinOnePercentOfTheFile) {
    CompressOptions wide = fine_index();
    wide.direction_bits = 16, wide.points_per_block = 300;
    const std::string wide_file = compressed("bundles/CST_R-step0.1.tck", "cst16.fft", wide);
    for (const std::string& path : {fiblet_file(), dwi_file(), wide_file}) {
        const FftFile file(path);
        const TrailerChunk* c = file.find_chunk(kBlockIndexTag);
        ASSERT_NE(c, nullptr);
        const FftHeader& h = file.header();
        const std::uint64_t count_bytes = h.points_per_block > 255 ? 2 : 1;
        EXPECT_EQ(c->payload[0], 4) << path;
        EXPECT_EQ(c->payload.size(), 64 + count_bytes * h.fibers + stream_bytes(c->payload)) << path;
        // The budget: 1 % of a file of long fibers (the per-fiber counts
        // make more of a file of short ones): about 6 bits a block.
        if (path == fiblet_file()) {
            EXPECT_LT(double(c->payload.size() + 16), 0.01 * double(file.file_size()));
        }
        const BlockIndex index = BlockIndex::load(file);
        EXPECT_EQ(index.source(), BlockIndex::Source::chunk);
        expect_boxes_hold_points(file, index, decode_everything(file));
    }
}

TEST_F(SelectIndex, CandidatesNeverMissABlockWithAPointInTheRegion) {
    for (const std::string& path : {fiblet_file(), shared_data("reference/small-ifod1.fft"), v2_file(), v3_file()}) {
        const FftFile file(path);
        const DecodedFile d = decode_everything(file);
        const BlockIndex index = BlockIndex::load(file);
        QueryGenerator gen(d, 5);
        std::size_t candidates = 0, hits = 0;
        for (int i = 0; i < 40; ++i) {
            const Region r = gen.region();
            std::vector<std::uint64_t> bits;
            if (r.shape == Region::Shape::sphere)
                index.blocks_near_sphere(r.center, r.radius, bits);
            else
                index.blocks_near_box(r.box, bits);
            for (std::size_t b = 0; b < d.blocks.size(); ++b) {
                candidates += has_bit(bits, b);
                if (any_inside(d, d.blocks[b].first_point, d.blocks[b].points, r)) {
                    ++hits;
                    ASSERT_TRUE(has_bit(bits, b)) << path << ": region " << i << " misses block " << b;
                }
            }
        }
        // Pruning works: a box per block (versions 3 and 4, computed) leaves most
        // blocks out and lets through few more than are hit.
        EXPECT_GE(candidates, hits) << path;
        if (path == v2_file() || path == v3_file()) continue;  // small files: regions cover much of them
        EXPECT_LT(candidates, 40 * d.blocks.size() / 4) << path;
        EXPECT_LT(candidates, 2 * hits) << path;
    }
}

TEST_F(SelectIndex, FrustumCandidatesCoverEveryBlockSphereThatMeetsTheFrustum) {
    for (const std::string& path : {fiblet_file(), dwi_file(), v2_file()}) {
        const FftFile file(path);
        const DecodedFile d = decode_everything(file);
        const BlockIndex index = BlockIndex::load(file);
        QueryGenerator gen(d, 9);
        std::size_t spheres = 0, near = 0, starting_near = 0;
        for (int i = 0; i < 20; ++i) {
            const Frustum f = frustum_from_camera(gen.camera());
            const float margin = index.max_sphere_radius() * (1 + 1e-5f) + 1e-3f;
            std::vector<std::uint64_t> by_box, by_first_point;
            index.blocks_near_frustum(f, margin, by_box);
            index.blocks_starting_near_frustum(f, margin, by_first_point);
            for (std::size_t b = 0; b < d.blocks.size(); ++b) {
                near += has_bit(by_box, b), starting_near += has_bit(by_first_point, b);
                if (sphere_intersects_frustum(f, d.blocks[b].sphere.center, d.blocks[b].sphere.radius)) {
                    ++spheres;
                    ASSERT_TRUE(has_bit(by_box, b)) << path << " camera " << i << " block " << b;
                    ASSERT_TRUE(has_bit(by_first_point, b)) << path << " camera " << i << " block " << b;
                }
            }
        }
        // The first points' boxes lie within the blocks' boxes (fewer let
        // through: BM_SelectQuery/Frustum measures how many fewer).
        EXPECT_LE(starting_near, near) << path;
        EXPECT_GT(spheres, 0u) << path;
    }
}

TEST_F(SelectIndex, FirstPointBoxHoldsTheFirstPointWithinTheBlocksBox) {
    // The frustum culls a block by its view sphere, centred on its first
    // point; the index narrows the block's box to where that point can be.
    for (const std::string& path : {fiblet_file(), dwi_file(), v2_file(), v3_file()}) {
        const FftFile file(path);
        const DecodedFile d = decode_everything(file);
        const BlockIndex index = BlockIndex::load(file);
        double own_volume = 0, first_volume = 0;
        for (std::size_t b = 0; b < d.blocks.size(); ++b) {
            const Aabb box = index.block_box(b), first = index.first_point_box(b);
            const Vec3f p = d.blocks[b].sphere.center;
            ASSERT_TRUE(p.x >= first.min.x && p.x <= first.max.x && p.y >= first.min.y && p.y <= first.max.y &&
                        p.z >= first.min.z && p.z <= first.max.z)
                << path << " block " << b;
            ASSERT_TRUE(first.min.x >= box.min.x && first.max.x <= box.max.x && first.min.y >= box.min.y &&
                        first.max.y <= box.max.y && first.min.z >= box.min.z && first.max.z <= box.max.z)
                << path << " block " << b;
            auto volume = [](const Aabb& a) {
                return double(a.max.x - a.min.x) * double(a.max.y - a.min.y) * double(a.max.z - a.min.z);
            };
            own_volume += volume(box), first_volume += volume(first);
        }
        if (path == v2_file()) EXPECT_EQ(first_volume, own_volume) << path;  // a box per group: no narrowing
        else EXPECT_LT(first_volume, 0.9 * own_volume) << path;  // 0.38 and 0.81 of it in the test files
    }
}

// The hierarchy's boxes are tested eight at a time in vector lanes
// (index/box_tests.hpp, leaf blocks unpacked from their grid cells there;
// partial leaves in AVX2 lanes, index/leaf_tests_avx2.hpp, where it runs):
// the candidates are exactly the blocks whose own box (block_box) meets the
// region by the one-box tests, and `inside` those it holds: none missed, none
// let through that its own box rules out.
TEST_F(SelectIndex, CandidatesAreTheBlocksWhoseOwnBoxMeetsTheRegion) {
    for (const std::string& path : {fiblet_file(), dwi_file(), v2_file(), v3_file()}) {
        const FftFile file(path);
        const BlockIndex index = BlockIndex::load(file);
        const DecodedFile d = decode_everything(file);
        QueryGenerator gen(d, 11);
        std::size_t near_count = 0, inside_count = 0;
        for (int i = 0; i < 30; ++i) {
            const Frustum f = frustum_from_camera(gen.camera());
            const float margin = gen.uniform(0, 2);
            for (const bool avx2 : {false, true}) {  // partial leaves: AVX2 lanes or four-float ones
                const test::ScopedSimdLoops loops(avx2);
                std::vector<std::uint64_t> bits;
                index.blocks_near_frustum(f, margin, bits);
                std::vector<std::uint64_t> starting;
                index.blocks_starting_near_frustum(f, margin, starting);
                for (std::size_t b = 0; b < d.blocks.size(); ++b) {
                    ASSERT_EQ(has_bit(bits, b), box_intersects_frustum(f, index.block_box(b), margin))
                        << path << " camera " << i << " block " << b << " AVX2 " << avx2;
                    ASSERT_EQ(has_bit(starting, b), box_intersects_frustum(f, index.first_point_box(b), margin))
                        << path << " camera " << i << " block " << b << " AVX2 " << avx2 << " (first point)";
                }
            }
            const Region r = gen.region();
            std::vector<std::uint64_t> near, inside;
            auto walk = [&](std::vector<std::uint64_t>& n, std::vector<std::uint64_t>& in) {
                if (r.shape == Region::Shape::sphere) index.blocks_near_sphere(r.center, r.radius, n, &in);
                else index.blocks_near_box(r.box, n, &in);
            };
            walk(near, inside);
            {  // the same blocks with the four-float lanes as with the AVX2 ones (the default)
                const test::ScopedSimdLoops loops(false);
                std::vector<std::uint64_t> near4, inside4;
                walk(near4, inside4);
                ASSERT_EQ(near4, near) << path << " region " << i;
                ASSERT_EQ(inside4, inside) << path << " region " << i;
            }
            for (std::size_t b = 0; b < d.blocks.size(); ++b) {
                const Aabb x = index.block_box(b);
                near_count += has_bit(near, b), inside_count += has_bit(inside, b);
                if (r.shape == Region::Shape::box) {
                    const Aabb& q = r.box;
                    ASSERT_EQ(has_bit(near, b), x.max.x >= q.min.x && x.min.x <= q.max.x && x.max.y >= q.min.y &&
                                                x.min.y <= q.max.y && x.max.z >= q.min.z && x.min.z <= q.max.z)
                        << path << " region " << i << " block " << b;
                    ASSERT_EQ(has_bit(inside, b), x.min.x >= q.min.x && x.max.x <= q.max.x && x.min.y >= q.min.y &&
                                                  x.max.y <= q.max.y && x.min.z >= q.min.z && x.max.z <= q.max.z)
                        << path << " region " << i << " block " << b;
                    continue;
                }
                // In double, away from the float tests' slack (1e-5 of r^2).
                double near2 = 0, far2 = 0;
                for (const auto& [v, lo, hi] : {std::tuple{r.center.x, x.min.x, x.max.x}, std::tuple{r.center.y, x.min.y, x.max.y},
                                               std::tuple{r.center.z, x.min.z, x.max.z}}) {
                    const double below = double(lo) - v, above = double(v) - hi;
                    near2 += std::pow(std::max({below, above, 0.0}), 2);
                    far2 += std::pow(std::max(double(v) - lo, double(hi) - v), 2);
                }
                const double r2 = double(r.radius) * r.radius;
                if (near2 < r2 * (1 - 1e-4)) {
                    ASSERT_TRUE(has_bit(near, b)) << path << " region " << i << " block " << b;
                }
                if (near2 > r2 * (1 + 1e-4)) {
                    ASSERT_FALSE(has_bit(near, b)) << path << " region " << i << " block " << b;
                }
                if (far2 < r2 * (1 - 1e-4)) {
                    ASSERT_TRUE(has_bit(inside, b)) << path << " region " << i << " block " << b;
                }
                if (far2 > r2) {
                    ASSERT_FALSE(has_bit(inside, b)) << path << " region " << i << " block " << b;
                }
            }
        }
        EXPECT_GT(near_count, inside_count) << path;  // both sides of each test visited
        EXPECT_GT(inside_count, 0u) << path;
    }
}

// A copy of `from` whose trailer's BIDX payload is replaced by `payload`,
// with a CSUM chunk that matches it: what a writer with a faulty index
// builder would make.
std::string with_index_payload(const FftFile& from, const std::vector<std::uint8_t>& payload, const std::string& to) {
    std::vector<TrailerChunk> chunks;
    for (const TrailerChunk& c : from.trailer())
        if (c.tag != kChecksumTag) chunks.push_back(c.tag == kBlockIndexTag ? TrailerChunk{c.tag, payload} : c);
    write_file(to, test::with_checksummed_trailer(read_file(from.path()), from.header(), chunks));
    return to;
}

// Whether `p` as the BIDX payload of a copy of `good` is refused with a
// clear error when the file opens or its index loads.
bool rejected(const FftFile& good, const std::vector<std::uint8_t>& p, const std::string& to) {
    try {
        const FftFile bad(with_index_payload(good, p, to));
        BlockIndex::load(bad);
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), Errc::fft_format);
        EXPECT_NE(std::string(e.what()).find("BIDX"), std::string::npos) << e.what();
        return true;
    }
    return false;
}

TEST_F(SelectIndex, MalformedChunksAreRejected) {
    const FftFile good(fiblet_file());
    const std::vector<std::uint8_t> payload = good.find_chunk(kBlockIndexTag)->payload;
    auto bad = [&](const std::vector<std::uint8_t>& p, const std::string& name) {
        return rejected(good, p, work_file(name));
    };
    EXPECT_FALSE(bad(payload, "same.fft"));
    auto p = payload;
    p.resize(30);
    EXPECT_TRUE(bad(p, "truncated.fft"));
    p = payload, p.pop_back();
    EXPECT_TRUE(bad(p, "short.fft"));
    p = payload, p.push_back(0);
    EXPECT_TRUE(bad(p, "long.fft"));
    p = payload, p[0] = 9;
    EXPECT_TRUE(bad(p, "version.fft"));
    p = payload, p[8] ^= 1;  // fiber count
    EXPECT_TRUE(bad(p, "fibers.fft"));
    p = payload, p[4] = 1;  // reserved
    EXPECT_TRUE(bad(p, "reserved.fft"));
    p = payload, std::memset(&p[36], 0, 4);  // cell 0
    EXPECT_TRUE(bad(p, "cell.fft"));
    p = payload, std::memset(&p[40], 0, 4);  // no grid levels
    EXPECT_TRUE(bad(p, "levels0.fft"));
    p = payload, std::memset(&p[40], 0xff, 4);  // more levels than 1024
    EXPECT_TRUE(bad(p, "levels.fft"));
    p = payload, p[64] = std::uint8_t(p[64] == 1 ? 2 : 1);  // first fiber's point count no longer adds up
    EXPECT_TRUE(bad(p, "points.fft"));
    p = payload, p[64] = 64;
    EXPECT_TRUE(bad(p, "toomany.fft"));
    const float nan = std::nanf(""), negative = -1;
    p = payload, std::memcpy(&p[48], &nan, 4);  // join distance
    EXPECT_TRUE(bad(p, "join-nan.fft"));
    p = payload, std::memcpy(&p[48], &negative, 4);
    EXPECT_TRUE(bad(p, "join-negative.fft"));
    p = payload, p[56] ^= 1;  // stream bytes: the payload size no longer matches
    EXPECT_TRUE(bad(p, "stream-size.fft"));
    // A stream cut short (its stated size with it): fewer boxes than blocks.
    p = payload, p.resize(p.size() - 8);
    const std::uint64_t shorter = stream_bytes(payload) - 8;
    std::memcpy(&p[56], &shorter, 8);
    EXPECT_TRUE(bad(p, "stream-short.fft"));
    // ... or with bytes after its boxes.
    p = payload, p.insert(p.end(), 8, 0x55);
    const std::uint64_t longer = stream_bytes(payload) + 8;
    std::memcpy(&p[56], &longer, 8);
    EXPECT_TRUE(bad(p, "stream-long.fft"));
    // The first fiber's first box, coded whole, at the last grid level:
    // later boxes, coded against it, fall off the grid.
    p = payload;
    const std::uint32_t one = 1;
    std::memcpy(&p[40], &one, 4);
    EXPECT_TRUE(bad(p, "offgrid.fft"));
    // Through the CLI: exit 4, the chunk named.
    const CommandResult r =
        run_cli("extract " + work_file("offgrid.fft") + " -o " + work_file("offgrid.tck") + " --include 0,0,0,5");
    EXPECT_EQ(r.status, 4) << r.output;
    EXPECT_NE(r.output.find("BIDX"), std::string::npos) << r.output;
}

TEST_F(SelectIndex, DamagedBoxStreamsAreRefusedOrStillHoldOnlyBoxes) {
    // Any bytes decode to some boxes: a damaged stream is refused (boxes off
    // the grid, a length that does not match) or loads; never a crash.
    const FftFile good(fiblet_file());
    const std::vector<std::uint8_t> payload = good.find_chunk(kBlockIndexTag)->payload;
    const std::size_t stream = payload.size() - stream_bytes(payload);
    std::size_t refused = 0;
    for (int i = 0; i < 16; ++i) {
        auto p = payload;
        p[stream + 5 + (p.size() - stream - 5) * std::size_t(i) / 16] ^= std::uint8_t(0x5a);
        refused += rejected(good, p, work_file("flip" + std::to_string(i) + ".fft"));
    }
    EXPECT_GT(refused, 8u);
}

TEST_F(SelectIndex, MalformedVersionTwoChunksAreRejected) {
    const FftFile good(v2_file());
    const std::vector<std::uint8_t> payload = good.find_chunk(kBlockIndexTag)->payload;
    auto bad = [&](const std::vector<std::uint8_t>& p, const std::string& name) {
        return rejected(good, p, work_file("v2-" + name));
    };
    EXPECT_FALSE(bad(payload, "same.fft"));
    auto p = payload;
    p = payload, p.pop_back();
    EXPECT_TRUE(bad(p, "short.fft"));
    p = payload, p[4] = 40;  // bits per box
    EXPECT_TRUE(bad(p, "bits.fft"));
    p = payload, std::memset(&p[40], 0xff, 4);  // levels overflow the code
    EXPECT_TRUE(bad(p, "levels.fft"));
    p = payload, std::memset(&p[52], 0, 4);  // 0 blocks per group
    EXPECT_TRUE(bad(p, "group0.fft"));
    p = payload, p[56] ^= 1;  // group count: the payload size no longer matches
    EXPECT_TRUE(bad(p, "groups.fft"));
    // Groups of 2 blocks with the same number of groups: well-formed on its
    // own, but the fibers' blocks make another number of groups.
    p = payload, p[52] = 2;
    EXPECT_TRUE(bad(p, "group2.fft"));
    p = payload, p[72] = std::uint8_t(p[72] == 1 ? 2 : 1);  // point counts
    EXPECT_TRUE(bad(p, "points.fft"));
    // Version 1's size rule (56-byte header, a box per block) applied to a
    // version-2 payload.
    p = payload, p[0] = 1;
    EXPECT_TRUE(bad(p, "v1.fft"));
}

// Codes of `bits` bits, least significant bit first, from byte `at`.
std::vector<std::uint32_t> unpack_codes(const std::vector<std::uint8_t>& p, std::size_t at, std::size_t n,
                                        unsigned bits) {
    std::vector<std::uint32_t> codes(n, 0);
    for (std::size_t k = 0; k < n * bits; ++k)
        codes[k / bits] |= std::uint32_t((p[at + k / 8] >> (k % 8)) & 1) << (k % bits);
    return codes;
}

void pack_codes(const std::vector<std::uint32_t>& codes, unsigned bits, std::vector<std::uint8_t>& out) {
    const std::size_t at = out.size();
    out.resize(at + (codes.size() * bits + 7) / 8, 0);
    for (std::size_t k = 0; k < codes.size() * bits; ++k)
        out[at + k / 8] |= std::uint8_t(((codes[k / bits] >> (k % bits)) & 1) << (k % 8));
}

TEST_F(SelectIndex, VersionOneChunksOfOneBoxPerBlockAreStillRead) {
    // Version 1 (fiblet before groups): the 56-byte header and a box per
    // block. Made from the version-2 chunk, each group's code given to each
    // of its blocks (same grid).
    const FftFile file(v2_file());
    const DecodedFile d = decode_everything(file);
    const std::vector<std::uint8_t> v2 = file.find_chunk(kBlockIndexTag)->payload;
    const auto groups = index_groups(file, 8);
    const std::size_t counts = file.header().fibers;  // one byte a fiber
    const std::vector<std::uint32_t> group_codes = unpack_codes(v2, 72 + counts, groups.size(), 28);
    std::vector<std::uint32_t> block_codes;
    for (std::size_t g = 0; g < groups.size(); ++g)
        block_codes.insert(block_codes.end(), groups[g].second - groups[g].first, group_codes[g]);
    std::vector<std::uint8_t> v1(v2.begin(), v2.begin() + 52);
    v1[0] = 1;
    v1.insert(v1.end(), 4, 0);  // reserved
    v1.insert(v1.end(), v2.begin() + 72, v2.begin() + 72 + std::ptrdiff_t(counts));
    pack_codes(block_codes, 28, v1);
    const FftFile old(with_index_payload(file, v1, work_file("v1.fft")));
    const BlockIndex index = BlockIndex::load(old);
    EXPECT_EQ(index.source(), BlockIndex::Source::chunk);
    EXPECT_EQ(index.groups(), index.blocks());
    EXPECT_LT(index.max_join(), 0.0f);  // unknown in version 1
    expect_boxes_hold_points(old, index, d);
    EXPECT_NO_THROW(verify_fft_file(old.path()));
    // Selections through it are the decode-everything reference's.
    expect_selections_match_brute_force(old, index, d, 3, 10, false, old.path());
}

// verify's verdict on a file, as the CLI gives it.
void expect_verify_fails_on_index(const std::string& path) {
    try {
        verify_fft_file(path);
        ADD_FAILURE() << "verify passed " << path;
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), Errc::fft_format);
        EXPECT_NE(std::string(e.what()).find("BIDX"), std::string::npos) << e.what();
    }
    EXPECT_EQ(run_cli("verify " + path).status, 4);
}

TEST_F(SelectIndex, VerifyCatchesAJoinBoundBelowARealJump) {
    // A writer that understated maxJoin: the file opens (well-formed), but a
    // selection could lose blocks; verify decodes them and says so.
    const FftFile good(fiblet_file());
    EXPECT_NO_THROW(verify_fft_file(good.path()));
    std::vector<std::uint8_t> p = good.find_chunk(kBlockIndexTag)->payload;
    const float small = 0.25f * BlockIndex::load(good).max_join();
    std::memcpy(&p[48], &small, 4);
    const std::string bad = with_index_payload(good, p, work_file("join.fft"));
    EXPECT_NO_THROW(FftFile{bad});
    expect_verify_fails_on_index(bad);
}

// A version-4 builder given `file`'s decoded blocks, block `moved`'s points
// shifted by `dx` mm along x (`first_only`: its first point alone).
IndexBuilder block_boxes_with_one_moved(const FftFile& file, const DecodedFile& d, std::size_t moved, float dx,
                                        bool first_only) {
    IndexBuilder builder(file.header(), BlockIndexFormat::block_boxes);
    for (std::size_t b = 0; b < d.blocks.size(); ++b) {
        std::vector<float> pts(&d.points.xyz[3 * d.blocks[b].first_point],
                               &d.points.xyz[3 * (d.blocks[b].first_point + d.blocks[b].points)]);
        if (b == moved)
            for (std::size_t k = 0; k < (first_only ? 1 : pts.size()); k += 3) pts[k] += dx;
        builder.add_block(pts.data(), d.blocks[b].points, d.blocks[b].last_of_fiber);
    }
    return builder;
}

TEST_F(SelectIndex, VerifyCatchesABlockBoxThatMissesAPoint) {
    // A builder given block 5's points 20 mm away: a well-formed chunk whose
    // box for block 5 misses the block.
    const FftFile file(dwi_file());
    const DecodedFile d = decode_everything(file);
    IndexBuilder builder = block_boxes_with_one_moved(file, d, 5, 20, false);
    const std::string bad = with_index_payload(file, builder.finish()->payload, work_file("box.fft"));
    EXPECT_NO_THROW(BlockIndex::load(FftFile{bad}));
    expect_verify_fails_on_index(bad);
}

TEST_F(SelectIndex, BlocksOffTheGridAreNeverCulled) {
    // Block 0's bounds replaced by a box far larger than any block: the
    // builder stores it as unbounded, and every query returns it.
    const FftFile file(dwi_file());
    const DecodedFile d = decode_everything(file);
    IndexBuilder builder = block_boxes_with_one_moved(file, d, 0, 1000, true);
    EXPECT_EQ(builder.unbounded_blocks(), 1u);
    const auto chunk = builder.finish();
    ASSERT_TRUE(chunk);
    const FftFile patched(with_index_payload(file, chunk->payload, work_file("unbounded.fft")));
    const BlockIndex index = BlockIndex::load(patched);
    EXPECT_GT(index.block_box(0).max.x, 1e20f);
    EXPECT_LT(index.block_box(1).max.x, 1e3f);
    EXPECT_FALSE(index.bounds()) << "no finite box holds block 0";
    std::vector<std::uint64_t> bits;
    index.blocks_near_sphere({-5000, 0, 0}, 1, bits);
    for (std::size_t b = 0; b < d.blocks.size(); ++b) EXPECT_EQ(has_bit(bits, b), b == 0) << "block " << b;
}

TEST_F(SelectIndex, BuilderRefusesLayoutsItCannotDescribe) {
    const FftFile file(dwi_file());
    IndexBuilder builder(file.header());
    const float pts[9] = {0, 0, 0, 0.1f, 0, 0, 0.2f, 0, 0};
    builder.add_block(pts, 3, false);  // partial, yet not the fiber's last block
    builder.add_block(pts, 3, true);
    EXPECT_FALSE(builder.finish());
    IndexBuilder fine(file.header());
    fine.add_block(pts, 3, true);
    EXPECT_TRUE(fine.finish());
}

TEST_F(SelectIndex, ParallelPartsJoinToTheSameChunk) {
    const std::string coarse = compressed("small-sdstream.tck", "sdstream-default.fft", CompressOptions{});
    for (const auto& [path, format] :
         {std::pair{fiblet_file(), BlockIndexFormat::block_boxes}, std::pair{coarse, BlockIndexFormat::group_boxes}}) {
        const FftFile file(path);
        const DecodedFile d = decode_everything(file);
        IndexBuilder whole(file.header(), format), first(file.header(), format), second(file.header(), format);
        EXPECT_EQ(whole.format(), format);
        for (std::size_t b = 0; b < d.blocks.size(); ++b) {
            const float* p = &d.points.xyz[3 * d.blocks[b].first_point];
            whole.add_block(p, d.blocks[b].points, d.blocks[b].last_of_fiber);
            (d.blocks[b].fiber < 400 ? first : second).add_block(p, d.blocks[b].points, d.blocks[b].last_of_fiber);
        }
        first.append(second);
        EXPECT_EQ(first.finish()->payload, whole.finish()->payload) << path;
        // ... and to what compress stored.
        EXPECT_EQ(whole.finish()->payload, file.find_chunk(kBlockIndexTag)->payload) << path;
    }
    // Parts of different formats do not join.
    const FftFile coarse_file(coarse);
    const FftHeader& h = coarse_file.header();  // the file outlives it
    IndexBuilder v2(h, BlockIndexFormat::group_boxes);
    EXPECT_THROW(v2.append(IndexBuilder(h, BlockIndexFormat::block_boxes)), Error);
}

}  // namespace
